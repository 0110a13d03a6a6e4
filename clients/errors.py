"""The client library's errors: every failure is an ``AdsError`` that names its code."""

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
    """No reply within the client's timeout (ADS 0x745 SYNCTIMEOUT)."""

    def __init__(self, message: str) -> None:
        super().__init__(AdsReturnCode.CLIENT_SYNCTIMEOUT, message)


class AdsConnectionError(AdsError, ConnectionError):
    """The client is not connected (ADS 0x748 PORTNOTOPEN) or got an unreadable reply."""


class ChannelError(Exception):
    """A program or manual block ended with the channel in ERROR; ``errors`` lists the
    channel's errors as ``"error <id>: <file>:<line>:<column>: <text>"`` lines."""

    def __init__(self, channel: int, errors: list[str]) -> None:
        text = "; ".join(errors) if errors else "no error text"
        super().__init__(f"channel {channel} went to ERROR: {text}")
        self.channel = channel
        self.errors = errors
