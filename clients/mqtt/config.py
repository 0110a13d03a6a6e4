"""What a bridge is told: service, broker, machine name, objects, and its timings."""

from __future__ import annotations

import ssl
from dataclasses import dataclass

from .topics import check_level

DEFAULT_MQTT_PORT = 1883
DEFAULT_MQTTS_PORT = 8883

#: The objects published when ``--objects`` is not given (globs, resolved by the service):
#: what a dashboard of the machine shows. ``@default`` in ``--objects`` stands for them.
DEFAULT_OBJECTS: tuple[str, ...] = (
    "ch*.mc_active_mode_r",  # 1 STANDBY, 2 AUTOMATIC, 3 MDI, 4 MANUAL
    "ch*.mc_active_state_r",  # 1 DESELECTED .. 4 ACTIVE, 5 HOLD, 6 ERROR
    "ch*.mc_active_program_name_r",
    "ch*.actual_block_number",  # N of the block in the interpolator
    "ch*.mc_active_file_name_r",  # file and line of that block
    "ch*.mc_active_line_r",
    "ch*.mc_wait_reason_r",  # why the channel stands: 0 NONE, 1 SINGLE_BLOCK, .. (name)
    "ch*.mc_wait_reason_text_r",  # the same as a sentence
    "ch*.ax*.command_position_acs",  # channel axes, 0.1 um
    "ax*.actual_position_acs",  # physical axes (drives), 0.1 um
    "ch*.ax*.link_state",  # 0 linked, 1 requested, 2 waiting for ack
    "ch*.mc_error_count_r",
    "ch*.mc_error_?_*_r",  # the 8 error slots: id, text, file, line, column, warning
)
DEFAULT_TOKEN = "@default"


def expand_patterns(patterns: tuple[str, ...] | list[str]) -> tuple[str, ...]:
    """``patterns`` with ``@default`` replaced by ``DEFAULT_OBJECTS``, each once."""
    out: list[str] = []
    for pattern in patterns:
        out.extend(DEFAULT_OBJECTS if pattern == DEFAULT_TOKEN else (pattern,))
    return tuple(dict.fromkeys(out))


def parse_broker(text: str, tls: bool = False) -> tuple[str, int]:
    """``HOST[:PORT]`` (IPv6 as ``[::1]:1883``) as (host, port); the port defaults to
    1883, or 8883 with TLS. ``ValueError`` with a readable message otherwise."""
    default_port = DEFAULT_MQTTS_PORT if tls else DEFAULT_MQTT_PORT
    if text.startswith("["):  # [IPv6] or [IPv6]:PORT
        host, bracket, rest = text[1:].partition("]")
        if not bracket or rest and not rest.startswith(":"):
            raise ValueError(f"broker {text!r}: expected [IPV6 ADDRESS]:PORT")
        port_text = rest[1:] if rest else None
    elif text.count(":") > 1:
        raise ValueError(f"broker {text!r}: write an IPv6 address as [ADDRESS]:PORT")
    else:
        host, colon, port_text = text.partition(":")
        port_text = port_text if colon else None
    if not host or any(c.isspace() for c in host):
        raise ValueError(f"broker {text!r}: expected HOST[:PORT]")
    if port_text is None:
        return host, default_port
    if not port_text.isdigit() or not 0 < int(port_text) < 65536:
        raise ValueError(f"broker {text!r}: the port must be a number 1..65535")
    return host, int(port_text)


@dataclass(frozen=True, slots=True)
class BridgeConfig:
    """Everything a ``Bridge`` needs. Timings are wall-clock seconds unless named ``_ms``
    (kernel time, as the service samples)."""

    endpoint: str  # the cnc-service, tcp://host:port
    broker_host: str
    machine: str  # one topic level: cnc/<machine>/...
    broker_port: int = DEFAULT_MQTT_PORT
    objects: tuple[str, ...] = DEFAULT_OBJECTS  # globs of objects to publish
    writable: tuple[str, ...] = ()  # globs of objects clients may write; none by default
    username: str | None = None
    password: str | None = None
    tls_context: ssl.SSLContext | None = None  # TLS to the broker when set
    client_id: str | None = None  # default cnc-mqtt-<machine>: one bridge per machine
    cycle_ms: int = 10  # the service checks each object for a change this often
    service_timeout_s: float = 2.0  # a request to the service without reply fails then
    probe_s: float = 1.0  # how often the bridge checks that the service is still the same
    reconnect_initial_s: float = 0.1  # backoff after a lost connection, doubling ...
    reconnect_max_s: float = 5.0  # ... up to this
    keepalive_s: int = 30  # MQTT keepalive: the broker sends the will this much later
    # (x 1.5) when the bridge's host vanishes without closing the connection
    key_file: str | None = None  # CURVE: the bridge's secret key file (service with --keys)
    server_key: str | None = None  # the service's public key (default: beside key_file)

    def __post_init__(self) -> None:
        check_level(self.machine, "machine name")
        object.__setattr__(self, "objects", expand_patterns(self.objects))
        if self.cycle_ms < 0:
            raise ValueError("cycle_ms must be >= 0")
        if not 0 < self.reconnect_initial_s <= self.reconnect_max_s:
            raise ValueError("reconnect delays need 0 < initial <= max")
        if self.service_timeout_s <= 0 or self.probe_s <= 0:
            raise ValueError("service_timeout_s and probe_s must be > 0")

    @property
    def mqtt_client_id(self) -> str:
        """The MQTT client id. A fixed id per machine makes a second bridge of the same
        machine take over the first one's session instead of running beside it."""
        return self.client_id or f"cnc-mqtt-{self.machine}"
