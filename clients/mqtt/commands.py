"""Write requests from MQTT: check, write through the client, and say what happened.

A request is refused before it reaches the service when it is malformed (0x70b), when
it was retained by the broker (0x704: a retained request would run again on every
connect), when the object is unknown (0x710, from the client's catalog), not matched by
``--writable`` (0x704) or the value does not fit the object's type (0x706). Otherwise the
service decides, and its ADS code is the reply's.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from cnc_objects.protocol.errors import AdsReturnCode

from ..errors import AdsConnectionError, AdsError
from . import payloads
from .payloads import REFUSED, RequestError
from .source import ServiceSource

log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class Outcome:
    """The reply to one request: its id (None: none usable) and the JSON body."""

    request_id: str | None
    body: bytes


async def execute_set(
    source: ServiceSource, name: str, payload: bytes, retained: bool, topic: str
) -> Outcome:
    """Carry out the write request ``payload`` (from ``topic``) for the object ``name``;
    never raises for anything the request or the service does wrong. A reply without
    request id names ``topic``, so that its sender can tell it is theirs."""
    try:
        request = payloads.decode_set(payload)
    except RequestError as exc:
        log.info("write request on %s refused: %s", topic, exc)
        return _refused(exc.request_id, exc.code, str(exc), topic)
    rid = request.request_id
    try:
        if retained:
            raise RequestError(REFUSED, "a retained write request is not executed "
                               "(it would run again at every connect); publish it unretained")
        client = source.client
        if client is None:
            raise AdsConnectionError(AdsReturnCode.CLIENT_PORTNOTOPEN,
                                     "the bridge is not connected to the service")
        info = await client.describe(name)
        if info.name.lower() not in source.writable:
            raise RequestError(REFUSED, f"{info.name} is not writable through this bridge "
                               "(not matched by --writable)")
        given = request.value if request.raw else payloads.from_engineering(info, request.value)
        value = payloads.coerce(info.dtype, given, info.name)
        await client.write(info.name, value)
    except (RequestError, AdsError) as exc:
        log.info("write request on %s refused: %s", topic, exc)
        return _refused(rid, exc.code, str(exc), topic)
    log.debug("wrote %s := %r (request %s)", info.name, value, rid)
    return Outcome(rid, payloads.encode_ok(None if rid else topic))


def _refused(request_id: str | None, code: int, error: str, topic: str) -> Outcome:
    return Outcome(request_id, payloads.encode_error(code, error, None if request_id else topic))
