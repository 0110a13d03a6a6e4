"""The ADS baseline: a minimal asyncio AMS/TCP server that answers every frame with one
fixed Read reply (4 bytes of data), addressed back to the sender. No dispatch, no lookup:
what any Python ADS server costs at least."""

from __future__ import annotations

import asyncio
import struct

_TCP = struct.Struct("<HI")
_HEADER = struct.Struct("<6sH6sHHHIII")
_DATA = struct.pack("<II", 0, 4) + b"\x00\x00\x00\x00"  # result 0, 4 bytes of data


class _Echo(asyncio.Protocol):
    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self.transport = transport
        self.buffer = b""

    def data_received(self, data: bytes) -> None:
        buffer = self.buffer + data
        pos = 0
        while len(buffer) - pos >= 6:
            length = _TCP.unpack_from(buffer, pos)[1]
            if len(buffer) - pos - 6 < length:
                break
            target, tport, source, sport, command, _, _, _, invoke = _HEADER.unpack_from(
                buffer, pos + 6)
            self.transport.write(  # type: ignore[attr-defined]
                _TCP.pack(0, 32 + len(_DATA))
                + _HEADER.pack(source, sport, target, tport, command, 5, len(_DATA), 0, invoke)
                + _DATA
            )
            pos += 6 + length
        self.buffer = buffer[pos:]


def serve_ads_echo(host: str, port: int, ready) -> None:  # runs in a second process
    """Listen on ``host:port``, put True on ``ready`` (or the error), answer forever."""

    async def main() -> None:
        try:
            server = await asyncio.get_running_loop().create_server(_Echo, host, port)
        except OSError as exc:
            ready.put(str(exc))
            return
        ready.put(True)
        async with server:
            await server.serve_forever()

    asyncio.run(main())
