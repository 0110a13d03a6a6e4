"""The MQTT topics of one machine, in one place.

    cnc/<machine>/<object name>     the object's value (retained, QoS 1)
    cnc/<machine>/status            "online" / "offline" (retained; "offline" is the will)
    cnc/<machine>/set/<object name> write requests, from any client
    cnc/<machine>/reply/<id>        the outcome of the write request that carried ``id``
    cnc/<machine>/reply             outcomes of requests without a usable id
    cnc/<machine>/alarms/active     the active alarms (retained; clients/mqtt/alarms.py)
    cnc/<machine>/alarms/event      one message per alarm event

Object names (``ch1.ax1.link_state``, ``gpCh[0].bahn_state.dist_prog_start``) contain no
``/``, ``+`` or ``#``, so each is one topic level and needs no escaping.
"""

from __future__ import annotations

from dataclasses import dataclass

ROOT = "cnc"
# Characters MQTT gives a meaning in topics (levels and wildcards), and the NUL it forbids.
_RESERVED = frozenset("/+#\x00")
MAX_ID_CHARS = 128  # a request id is one topic level: keep it well below topic limits


def check_level(text: str, what: str) -> str:
    """``text`` if it can be one topic level (non-empty, no ``/``, ``+``, ``#``, NUL);
    else ``ValueError`` naming ``what``."""
    if not text:
        raise ValueError(f"{what} is empty")
    bad = sorted(_RESERVED.intersection(text))
    if bad:
        raise ValueError(f"{what} {text!r} contains {', '.join(map(repr, bad))}")
    return text


@dataclass(frozen=True, slots=True)
class Topics:
    """Topic names of the machine ``machine`` (validated: one topic level)."""

    machine: str

    def __post_init__(self) -> None:
        check_level(self.machine, "machine name")

    @property
    def base(self) -> str:
        """``cnc/<machine>``."""
        return f"{ROOT}/{self.machine}"

    @property
    def status(self) -> str:
        """Where ``online`` / ``offline`` is published."""
        return f"{self.base}/status"

    @property
    def set_filter(self) -> str:
        """The subscription that receives every write request."""
        return f"{self.base}/set/#"

    @property
    def no_id_reply(self) -> str:
        """Replies to requests that carry no usable id."""
        return f"{self.base}/reply"

    @property
    def alarm_list(self) -> str:
        """Where the active alarms are published (retained)."""
        return f"{self.base}/alarms/active"

    @property
    def alarm_event(self) -> str:
        """Where each alarm event is published."""
        return f"{self.base}/alarms/event"

    def value(self, name: str) -> str:
        """The topic of object ``name``'s value."""
        return f"{self.base}/{name}"

    def set(self, name: str) -> str:
        """The topic a client publishes to, to write ``name``."""
        return f"{self.base}/set/{name}"

    def reply(self, request_id: str) -> str:
        """The topic of the reply to the request ``request_id`` (checked elsewhere)."""
        return f"{self.base}/reply/{request_id}"

    def object_of_set(self, topic: str) -> str | None:
        """The object name of a write-request topic, or None if ``topic`` is not one."""
        prefix = f"{self.base}/set/"
        if not topic.startswith(prefix):
            return None
        return topic[len(prefix):]
