"""What an ADS answer must be in the raw tests: the codes and lengths expected of a reply."""

from __future__ import annotations

import struct

from tests.support.ads_raw import (
    PLC,
    RawAds,
)

ANY = 0xFFFF_FFFF  # "I do not know the size"


PER_ITEM = 0xFFFF  # what ads-client sends per item of a sum command


OK, INVALIDSIZE, SYMBOLNOTFOUND = 0, 0x705, 0x710


def answer(ads: RawAds, command: int, data: bytes, port: int = PLC) -> tuple[int, bytes]:
    """(result, data) of a Read or ReadWrite; the announced length matches the data."""
    got = ads.call(command, data, port=port)
    result, length = struct.unpack_from("<II", got.data)
    assert len(got.data) == 8 + length
    return result, got.data[8:]
