"""The client library's errors.

What the service (or the connection to it) refused is an ``AdsError`` that names its ADS
code. What the client refused itself, before anything was sent (a value outside its
type's range, an unknown type or state name), is a ``ClientValueError``: it claims no ADS
code, because no device said anything.
"""

from __future__ import annotations

from cnc_objects.protocol.errors import AdsReturnCode, describe_code


class AdsError(Exception):
    """An ADS request failed. ``code`` is the ADS return code; the message names it:
    ``ADS 0x704 INVALIDACCESS: ch1.mc_command_execution_mode_w is write-only``."""

    def __init__(self, code: int, message: str = "") -> None:
        self.code = int(code)
        self.detail = message
        text = f"ADS {describe_code(self.code)}"
        super().__init__(f"{text}: {message}" if message else text)


class AdsTimeoutError(AdsError, TimeoutError):
    """No reply within the client's timeout, or a wait that did not end in time
    (ADS 0x745 SYNCTIMEOUT)."""

    def __init__(self, message: str) -> None:
        super().__init__(AdsReturnCode.CLIENT_SYNCTIMEOUT, message)


class NoReplyError(AdsTimeoutError):
    """No reply within the client's timeout. ``request`` names what was asked, in the
    caller's words where the client knows them (``READ ch1.x``), else the ADS command
    that went unanswered (``BROWSE``)."""

    def __init__(self, request: str, timeout_s: float, endpoint: str) -> None:
        self.request = request
        self.timeout_s = timeout_s
        self.endpoint = endpoint
        super().__init__(f"no reply to {request} within {timeout_s:g} s from {endpoint} "
                         "(is cnc-service running?)")

    def asking(self, request: str) -> NoReplyError:
        """The same timeout, named after ``request`` (what the caller asked for): a read
        by name first describes the name, and its BROWSE is not what the user asked."""
        return NoReplyError(request, self.timeout_s, self.endpoint)


class AdsConnectionError(AdsError, ConnectionError):
    """The client is not connected (ADS 0x748 PORTNOTOPEN) or got an unreadable reply."""


class AuthenticationError(AdsConnectionError):
    """The service would not let this client in (ADS 0x723 ACCESSDENIED): its CURVE key
    was refused, or the keys do not fit the service (``clients.curve``). The connection
    is closed; the message says what to change."""

    def __init__(self, message: str) -> None:
        super().__init__(AdsReturnCode.DEVICE_ACCESSDENIED, message)


class ServiceFullError(AdsConnectionError):
    """The service had no room for this connection (ADS 0x708 DEVICE_BUSY): its
    connection table is full of keyed or busy connections (``[limits]
    connections_per_front_end``). Not a key problem; try again later, or ask the
    service's operator for a larger table. The connection is closed."""

    def __init__(self, message: str) -> None:
        super().__init__(AdsReturnCode.DEVICE_BUSY, message)


class ClientValueError(ValueError):
    """The client refused a value before sending anything: outside its type's range, of
    the wrong Python type, an unknown type or ADS state name. Not an ``AdsError``: no
    device answered. ``str(exc)`` is the whole message, e.g.
    ``ch1.mc_command_feed_override_w: value -5 out of range for UNS16 (0..65535)``."""


class ChannelError(Exception):
    """A program or manual block ended with the channel in ERROR; ``errors`` lists the
    channel's errors as ``"error <id>: <file>:<line>:<column>: <text>"`` lines."""

    def __init__(self, channel: int, errors: list[str]) -> None:
        text = "; ".join(errors) if errors else "no error text"
        super().__init__(f"channel {channel} went to ERROR: {text}")
        self.channel = channel
        self.errors = errors
