"""cnc-objects: a CNC kernel whose state is typed CNC objects at ADS addresses.

The distribution installs this one top-level package. Its subpackages live in the
repository's top-level folders and are mapped here by setuptools' ``package-dir``:

- ``cnc_objects.protocol``: the wire (sans I/O)
- ``cnc_objects.objects``: the object model and catalog
- ``cnc_objects.service``: the running system (kernel, server, program store)
- ``cnc_objects.clients``: the client library, ``cnc``, ``cnc-hmi``, ``cnc-mqtt``
- ``cnc_objects.testing``: the pytest plugin for integration tests against a service
"""

from . import _native

_native.install()  # the compiled kernel hot path, when built and current
