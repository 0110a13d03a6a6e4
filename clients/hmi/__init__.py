"""``cnc-hmi``: a keyboard-driven terminal HMI (textual) of a cnc-objects service.

Channels, axes, program control, the jog-of-path switchover and the contour look-ahead,
updated by subscriptions (ADS notifications). Entry point: ``cnc_objects.clients.hmi.app:main``;
screens and key bindings are described in ``docs/hmi.md``.
"""
