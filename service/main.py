"""``cnc-service``: the composition root. Builds kernel, address space and servers, runs them.

    cnc-service [--config FILE] [--machine NAME] [--endpoint URL] [--ads HOST[:PORT]|off] [--ams-net-id ID]
                [--opcua opc.tcp://HOST[:PORT]|off]
                [--keys DIR] [--insecure]
                [--clock realtime|virtual|virtual-step|step] [--speed X] [--cycle-ms MS]
                [--samples latest|repeatable]
                [--program-dir DIR | --data-dir DIR] [--output-dir DIR] [--log-level L]

Two front ends over one dispatcher: ZeroMQ (``--endpoint``) and ADS over AMS/TCP
(``--ads``, default 127.0.0.1:48898, for pyads and every other ADS client); a third, OPC
UA (``--opcua``, default opc.tcp://127.0.0.1:4840, OPC 40502 CNC; docs/opcua.md), over
the same backend (``OPC UA on opc.tcp://... (...)``). Logs where
its program store is (``program store: /abs/path (why)``, see ``data_location``) and its
output area (``output area: /abs/path (why)``: the files the kernel writes), where
ADS listens (``ADS on 127.0.0.1:48898, AMS Net ID 127.0.0.1.1.1 ...``) and then the
ZeroMQ endpoint (``listening on tcp://...``, the last start-up line); SIGINT and SIGTERM
stop it cleanly (sockets closed, cycle thread joined, queued files written) with exit
code 0 within 5 s, whatever runs (``KERNEL_STOP_S`` + ``WRITER_STOP_S``). Bad usage, a bad
configuration or an address that cannot be bound exits with code 2 and says why (one
line, or one line per configuration problem).

Access (docs/security.md): ``--keys DIR`` (or ``[security]``) turns CURVE on for ZeroMQ,
each client key with a role. Without keys the ZeroMQ endpoint must be a loopback
address, and without ``[[ads.routes]]`` so must the ADS address: anything else is
refused (exit 2) unless ``--insecure`` says that the network is trusted (inside a
container, where the published port is the boundary).
"""

from __future__ import annotations

import asyncio
import gc
import logging
import os
import signal
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import NoReturn

import typer
import zmq

from cnc_objects.objects.plc_structs import PlcStructs
from cnc_objects.protocol.ams import parse_net_id
from cnc_objects.protocol.roles import LOOPBACK_ROLE, Role

from .ads.routes import Route, RouteTable
from .ads.server import AdsTcpServer
from .ads.symbols import SymbolService
from .backend import Backend
from .binding import build_address_space
from .config import ClockConfig, ConfigError, SampleMode, ServiceConfig, load_config
from .frontend_config import parse_ads_endpoint
from .kernel.alarms import AlarmLog
from .kernel.clock import Clock, RealtimeClock, VirtualClock
from .kernel.kernel import Kernel
from .kernel.nc.source import NcText
from .kernel.realtime_priority import DEFAULT_RT_PRIORITY, RT_PRIORITY_MAX, serve_below
from .kernel.state import Snapshot
from .kernel.step_clock import STEP_MAX_CYCLES, StepClock
from .limits import LimitsConfig, notification_limits, rate_limiter
from .machine_config import EmbeddedMachine
from .notifications import NotificationCounts
from .opcua.config import parse_opcua_endpoint
from .opcua.host import OpcUaProcess, OpcUaRefused, Ready
from .opcua.security_config import OpcUaSecurity
from .output_service import OutputService
from .program_service import ProgramStoreService
from .security import (
    SecurityError,
    ServerCurve,
    endpoint_is_local,
    host_is_loopback,
    load_server_curve,
)
from .server import ZmqServer
from .storage.data_location import (
    OPERATOR_DATA_NAME,
    StoreLocation,
    operator_data_location,
    output_area_location,
    program_store_location,
)
from .storage.operator_data_store import OperatorDataStore
from .storage.output_area import OutputArea
from .storage.output_writer import OutputLimits, OutputWriter
from .storage.program_store import ProgramStore, StoreError

log = logging.getLogger("cnc-service")

DEFAULT_ENDPOINT = "tcp://127.0.0.1:5555"
EXIT_USAGE = 2
KERNEL_STOP_S = 2.0  # at SIGTERM: the cycle thread gets this long to end
WRITER_STOP_S = 2.0  # then the output writer this long to write what is queued
#: Under SCHED_FIFO the GIL switch interval is the cycle time divided by this (issue 37).
SWITCH_CYCLE_FRACTION_FIFO = 2


class ClockKind(StrEnum):
    """What the cycle task runs on."""

    REALTIME = "realtime"  # sleep to each cycle deadline
    VIRTUAL = "virtual"  # no sleeping: kernel time runs as fast as the CPU allows (or --speed),
    # the cycles between two events in bulk
    VIRTUAL_STEP = "virtual-step"  # the same, every cycle run and published one by one
    STEP = "step"  # no cycle until a client grants cycles (cnc_cycle_step_w)


class LogLevel(StrEnum):
    """The levels ``--log-level`` accepts."""

    DEBUG = "DEBUG"  # everything
    INFO = "INFO"  # start, stop, what the service listens on (the default)
    WARNING = "WARNING"  # problems the service survives
    ERROR = "ERROR"  # problems only


app = typer.Typer(add_completion=False)


def _usage(message: str) -> NoReturn:
    print(f"cnc-service: {message}", file=sys.stderr)
    raise typer.Exit(EXIT_USAGE)


def make_clock(kind: ClockKind, cycle_s: float, speed: float | None,
               step_max_cycles: int = STEP_MAX_CYCLES,
               rt_priority: int = DEFAULT_RT_PRIORITY) -> Clock:
    """The clock the cycle task runs on (``rt_priority``: the realtime clock's SCHED_FIFO
    priority, 0 for none)."""
    if kind is ClockKind.REALTIME:
        return RealtimeClock(cycle_s, rt_priority)
    if kind is ClockKind.STEP:
        return StepClock(cycle_s, step_max_cycles)
    return VirtualClock(cycle_s, speed, event_speed=kind is ClockKind.VIRTUAL)


def _kernel_loader(
    store: ProgramStore,
) -> tuple[Callable[[str], NcText], Callable[[str], bool]]:
    """The store as the kernel sees it: a program's file by name (the decoder reads it as
    a stream, page by page), KeyError when absent."""

    def load(name: str) -> NcText:
        try:
            return store.path_of(name)
        except StoreError:
            raise KeyError(name) from None

    return load, store.exists


@dataclass(frozen=True)
class AdsListen:
    """Where the ADS front end listens and as which AMS Net ID (None: the default)."""

    host: str
    port: int
    net_id: str | None
    loopback_role: Role = LOOPBACK_ROLE  # of peers on loopback (and of all, when open)
    open_to_all: bool = False  # --insecure without routes: peers need no route


@dataclass(frozen=True)
class OpcUaListen:
    """Where the OPC UA front end listens and its security (``[opcua]``)."""

    host: str
    port: int
    security: OpcUaSecurity = field(default_factory=OpcUaSecurity)


async def serve(
    config: ServiceConfig, endpoint: str, clock_kind: ClockKind, speed: float | None,
    store: ProgramStore, ads: AdsListen | None = None, curve: ServerCurve | None = None,
    outputs: OutputArea | None = None, operator_data: Path | None = None,
    opcua: OpcUaListen | None = None,
) -> int:
    """Run kernel and the front ends until SIGINT or SIGTERM (ADS when ``ads`` is given,
    OPC UA when ``opcua`` is; ZeroMQ with CURVE when ``curve`` is given). The files the kernel writes go to
    ``outputs`` (default: ``<store>-output`` beside the store); the tool list and zero
    offsets are kept in ``operator_data`` (default: beside the store)."""
    loop = asyncio.get_running_loop()
    # The cycle thread must get the GIL soon after it wakes, even while the server is busy.
    switch_s = min(0.005, config.cycle_ms / 1000.0 / 4)
    if clock_kind is ClockKind.REALTIME and config.rt_priority:
        # before any thread of the service starts: they inherit the policy (the cycle
        # thread then asks for its own priority, one above)
        served = serve_below(config.rt_priority)
        log.info("service threads under %s", f"SCHED_FIFO priority {served.priority}"
                 if served.priority else "SCHED_OTHER")
        if served.priority:
            # No other process delays a GIL hand-over now. The interval trades the cycle's
            # wait for the GIL when it wakes (p99) against the times another thread takes
            # the GIL from it inside a cycle (overruns): half a cycle, 0.09 % overruns and
            # p99 510 us against 0.29 % and 440 us at a tenth (issue 37, docs/kernel.md).
            switch_s = config.cycle_ms / 1000.0 / SWITCH_CYCLE_FRACTION_FIFO
    sys.setswitchinterval(switch_s)
    opcua_process = None
    if opcua is not None:  # now: it imports asyncua while the kernel is built here; under
        # the policy the service's threads have (the in-process front end had it too)
        opcua_process = await _spawn_opcua(opcua, config.limits)
    log.info("GIL switch interval %g ms", switch_s * 1000.0)
    load, exists = _kernel_loader(store)
    limits = config.limits
    if outputs is None:
        outputs = OutputArea(store.root.with_name(store.root.name + "-output"))
    writer = OutputWriter(outputs, OutputLimits(
        limits.output_max_files, limits.output_max_file_bytes, limits.output_max_total_bytes,
        limits.output_queue_max_bytes))
    clock = make_clock(clock_kind, config.cycle_ms / 1000.0, speed, limits.step_max_cycles,
                       config.rt_priority)
    if operator_data is None:
        operator_data = store.root.with_name(f"{store.root.name}-{OPERATOR_DATA_NAME}")
    kept = OperatorDataStore(operator_data, config.machine)
    alarms = AlarmLog(limits.alarm_history_max, limits.alarm_active_max)
    repeatable = config.clock.samples is SampleMode.REPEATABLE
    kernel = Kernel(
        config.machine, clock, load, exists,
        writer.kernel_file, writer.save, check_max_errors=config.limits.check_max_errors,
        idle_steps_max=limits.decoder_idle_steps_max,
        alarms=alarms, tables=kept.load(alarms), repeatable=repeatable,
    )
    counts = NotificationCounts()  # the hub counts, cnc_notifications_r shows
    space = build_address_space(kernel, counts)
    structs = PlcStructs(space)  # the HLI's structs and arrays over the PLC symbols
    backend = Backend(space, kernel, loop, ProgramStoreService(store),
                      SymbolService(space, structs),
                      notification_limits(limits), counts,
                      outputs=OutputService(writer), structs=structs,
                      jog_hold_timeout_s=limits.jog_hold_timeout_s,
                      repeatable_samples=repeatable)
    kernel.on_cycle_end = _both(backend.hub.kernel_cycle_end,  # one hub serves both front ends
                                kept.observe)  # the tables, written by a thread of its own
    kernel.next_observed_ns = backend.hub.next_observed_ns  # cycles it must see
    try:
        server = ZmqServer(backend, endpoint, curve=curve, limits=limits)
    except zmq.ZMQError as exc:
        print(f"cnc-service: cannot listen on {endpoint}: {zmq.strerror(exc.errno or 0)}",
              file=sys.stderr)
        if opcua_process is not None:
            await opcua_process.close()
        return EXIT_USAGE
    ads_server = None
    if ads is not None:
        ads_server = await _start_ads(backend, config, ads)
        if ads_server is None:
            if opcua_process is not None:
                await opcua_process.close()
            server.close()
            writer.close()
            return EXIT_USAGE
    opcua_ready = None
    if opcua_process is not None:
        opcua_ready = await _start_opcua(opcua_process, backend)
        if opcua_ready is None:
            if ads_server is not None:
                ads_server.close()
            server.close()
            writer.close()
            return EXIT_USAGE
    stop = asyncio.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    # What start-up built (catalog, address space, configuration, imported modules) lives
    # as long as the service: out of the collector's way. A full collection over it held
    # the GIL for 20-40 ms under load, and the cycle waited (make bench, part jitter).
    gc.freeze()
    kept.start()
    kernel.start()
    server.start()
    if ads_server is not None:
        host, port = ads_server.address
        log.info("ADS on %s:%d, AMS Net ID %s (AMS ports %s; %d routes besides loopback, "
                 "%s role %s)",
                 f"[{host}]" if ":" in host else host, port, ads_server.net_id_text,
                 ", ".join(str(p) for p in sorted(ads_server.ports)), len(ads_server.routes),
                 "every peer's" if ads.open_to_all else "loopback",  # type: ignore[union-attr]
                 ads.loopback_role.label)  # type: ignore[union-attr]
    if opcua_ready is not None:
        log.info("OPC UA on %s (OPC 40502 CncInterface, OPC 40501-1 MachineTool, %d channels; "
                 "%s; built in %.2f s, %s; process %d)",
                 opcua_ready.url, len(config.channels), opcua_ready.security_note,
                 opcua_ready.start_s, opcua_ready.cache_note, opcua_ready.pid)
    if curve is not None:
        log.info("CURVE on: server public key %s; allow-list %s (%s)",
                 curve.public_key.decode(), curve.allow_list.origin, curve.allow_list.census())
    log.info(
        "listening on %s (machine %s, %d channels, %d objects, %s clock, cycle %g ms, "
        "%s samples)",
        server.endpoint, config.name, len(config.channels), len(space), clock_kind,
        config.cycle_ms, config.clock.samples,
    )
    try:
        await stop.wait()
    finally:
        log.info("stopping")
        if opcua_process is not None:
            await opcua_process.close()
        if ads_server is not None:
            ads_server.close()
        server.close()
        if backend.programs is not None:
            backend.programs.close()  # an index of a program under way is not waited for
        kernel.on_cycle_end = None
        backend.hub.close()  # a cycle that waits for a pass (repeatable samples) goes on
        writer.refuse_new()  # a program in a write loop stops now, its cycle with it
        kernel.close(KERNEL_STOP_S)
        writer.close(WRITER_STOP_S)  # what was queued before is written
        kept.close(WRITER_STOP_S)  # the tables as the kernel left them are written
    log.info("stopped")
    return 0


def _both(first: Callable[[Snapshot], None], second: Callable[[Snapshot], None]
          ) -> Callable[[Snapshot], None]:
    """One cycle hook that calls ``first``, then ``second``."""
    def hook(snapshot: Snapshot) -> None:
        first(snapshot)
        second(snapshot)

    return hook


async def _start_ads(
    backend: Backend, config: ServiceConfig, ads: AdsListen
) -> AdsTcpServer | None:
    """The listening ADS front end, or None after saying in one line why it cannot be."""
    routes = RouteTable(
        (Route.parse(r.name, r.net_id, r.address, r.role) for r in config.ads.routes),
        ads.loopback_role, ads.open_to_all,
    )
    ads_server = AdsTcpServer(backend, routes, config.ads.max_frame_bytes,
                              rate_limiter(config.limits), config.limits)
    try:
        await ads_server.start(ads.host, ads.port, ads.net_id)
    except OSError as exc:
        # errno for a bind failure; a host name that does not resolve has its own text
        reason = os.strerror(exc.errno) if exc.errno and exc.errno > 0 else exc.strerror or str(exc)
        print(f"cnc-service: cannot listen for ADS on {ads.host}:{ads.port}: {reason}",
              file=sys.stderr)
        return None
    return ads_server


async def _spawn_opcua(opcua: OpcUaListen, limits: LimitsConfig) -> OpcUaProcess:
    """The OPC UA process, spawned: it imports asyncua while the service builds its kernel
    (docs/opcua.md "One process of its own")."""
    process = OpcUaProcess(opcua.host, opcua.port, opcua.security, limits)
    await process.spawn()
    return process


async def _start_opcua(process: OpcUaProcess, backend: Backend) -> Ready | None:
    """The OPC UA process serving, or None after saying in one line why it cannot."""
    try:
        return await process.start(backend)
    except OpcUaRefused as exc:
        print(f"cnc-service: {exc}", file=sys.stderr)
        await process.close()
        return None


@app.command(
    epilog="Exit codes: 0 stopped by SIGINT or SIGTERM; 2 bad usage, bad configuration, "
    "unusable program store, endpoint, ADS or OPC UA address in use."
)
def run(
    config_file: Path | None = typer.Option(
        None, "--config", metavar="FILE",
        help="TOML machine configuration laid over the default.",
    ),
    endpoint: str = typer.Option(
        DEFAULT_ENDPOINT, "--endpoint", metavar="URL",
        help="ZeroMQ endpoint to bind (tcp://127.0.0.1:* picks a free port).",
    ),
    clock: ClockKind = typer.Option(ClockKind.REALTIME, "--clock", help="Clock of the cycle task."),
    speed: float | None = typer.Option(
        None, "--speed", metavar="X",
        help="Virtual clock: times real time (default: as fast as the CPU allows while busy).",
    ),
    cycle_ms: float | None = typer.Option(
        None, "--cycle-ms", metavar="MS", help="Cycle time in ms (overrides the configuration).",
    ),
    machine: EmbeddedMachine = typer.Option(
        EmbeddedMachine.THREE_AXIS, "--machine",
        help="Embedded machine that --config is laid over: three-axis (X Y Z), "
        "five-axis-ac (table-table A/C) or five-axis-bc (head-table B/C).",
    ),
    samples: SampleMode | None = typer.Option(
        None, "--samples",
        help="How subscriptions are sampled: latest (the kernel never waits for a reader) "
        "or repeatable (every due sample, none dropped: a slow reader slows the kernel; "
        "virtual and step clocks; default: [clock] samples of the configuration, else "
        "latest).",
    ),
    rt_priority: int | None = typer.Option(
        None, "--rt-priority", metavar="N", min=0, max=RT_PRIORITY_MAX,
        help="Realtime clock: SCHED_FIFO priority 1..99 of the cycle thread, with memory "
        f"locked, where permitted; 0: a normal thread (default: rt_priority of the "
        f"configuration, else {DEFAULT_RT_PRIORITY}).",
    ),
    program_dir: Path | None = typer.Option(
        None, "--program-dir", metavar="DIR",
        help="Directory of the program store (default: programs/ in --data-dir, else "
        "program_store_dir or data_dir/programs of the configuration, else "
        "./cnc-data/programs in the working directory).",
    ),
    data_dir: Path | None = typer.Option(
        None, "--data-dir", metavar="DIR",
        help="Data directory of this service: its programs/ is the program store, its "
        "output/ the output area.",
    ),
    output_dir: Path | None = typer.Option(
        None, "--output-dir", metavar="DIR",
        help="Directory of the output area, the files the kernel writes (default: output_dir "
        "of the configuration, else output/ in the data directory, else <program dir>-output "
        "beside --program-dir).",
    ),
    ads: str | None = typer.Option(
        None, "--ads", metavar="HOST[:PORT]",
        help="Where ADS clients (pyads, TwinCAT tools) connect: AMS/TCP address, port 48898 "
        "when left out; off disables ADS (default: [ads] endpoint of the configuration, "
        "else 127.0.0.1:48898).",
    ),
    ams_net_id: str | None = typer.Option(
        None, "--ams-net-id", metavar="NETID",
        help="AMS Net ID of the service (default: [ads] net_id, else the ADS address + .1.1).",
    ),
    opcua: str | None = typer.Option(
        None, "--opcua", metavar="URL",
        help="Where OPC UA clients (UaExpert, umati dashboards) connect: opc.tcp://HOST[:PORT], "
        "port 4840 when left out; off disables OPC UA (default: [opcua] endpoint of the "
        "configuration, else opc.tcp://127.0.0.1:4840; loopback only, docs/opcua.md).",
    ),
    keys: Path | None = typer.Option(
        None, "--keys", metavar="DIR",
        help="CURVE for ZeroMQ: DIR holds server.key_secret and the allow-list "
        "clients/<monitor|operator|admin>/*.key (default: [security] of the configuration; "
        "docs/security.md).",
    ),
    insecure: bool = typer.Option(
        False, "--insecure",
        help="Serve a non-loopback address without keys (ZeroMQ) or routes (ADS): anyone "
        "who reaches it may do everything. Only where the network is the boundary.",
    ),
    log_level: LogLevel = typer.Option(LogLevel.INFO, "--log-level", help="Lowest level logged."),
) -> None:
    """CNC kernel serving its objects over ZeroMQ and ADS (AMS/TCP)."""
    logging.basicConfig(
        level=log_level.value, format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        stream=sys.stderr,
    )
    if speed is not None and (clock is ClockKind.REALTIME or speed <= 0):
        _usage("--speed takes a positive factor and needs --clock virtual or virtual-step")
    config = _machine_config(config_file, cycle_ms, machine)
    if rt_priority is not None:  # typer checked the range
        config = config.model_copy(update={"rt_priority": rt_priority})
    if samples is not None:
        config = config.model_copy(update={"clock": ClockConfig(samples=samples)})
    if config.clock.samples is SampleMode.REPEATABLE and clock is ClockKind.REALTIME:
        _usage("repeatable samples (--samples or [clock] samples) need --clock virtual, "
               "virtual-step or step: the realtime clock cannot wait for a reader")
    location = program_store_location(
        program_dir, data_dir, config.program_store_dir, config.data_dir
    )
    curve = _server_curve(config, keys)
    if curve is None and not insecure and not endpoint_is_local(endpoint):
        _usage(f"{endpoint} is not a loopback address and no keys are given: anyone who "
               "reaches it could write every object; give --keys DIR (docs/security.md), "
               "bind 127.0.0.1, or --insecure")
    listen = _ads_listen(config, ads, ams_net_id, curve is not None, insecure)
    opcua_listen = _opcua_listen(config, opcua, curve is not None)
    store = _open_store(location, config)
    outputs = _open_outputs(output_dir, config, location)
    kept = operator_data_location(data_dir, config.data_dir, location)
    log.info("operator data file: %s (%s)", kept.path, kept.source)
    raise typer.Exit(asyncio.run(
        serve(config, endpoint, clock, speed, store, listen, curve, outputs, kept.path,
              opcua_listen)))


def _server_curve(config: ServiceConfig, keys: Path | None) -> ServerCurve | None:
    """The CURVE keys of ``--keys`` or ``[security]``, None when neither turns CURVE on."""
    security = config.security
    if keys is None and not security.curve:
        return None
    try:
        return load_server_curve(
            keys if keys is not None else _path(security.keys_dir),
            None if keys is not None else _path(security.server_secret_key_file),
            _path(security.clients_dir),
            [(c.name, c.public_key, c.role) for c in security.clients],
        )
    except SecurityError as exc:
        _usage(f"bad keys: {exc}")


def _path(text: str | None) -> Path | None:
    return Path(text).expanduser() if text else None


def _ads_listen(
    config: ServiceConfig, ads: str | None, net_id: str | None, keys: bool = False,
    insecure: bool = False,
) -> AdsListen | None:
    """Where ADS listens: ``--ads``/``--ams-net-id`` over the configuration's [ads]; and
    whom it serves: a non-loopback address needs routes (or ``insecure``: then every peer
    is served as if on loopback); loopback peers get ``[ads] loopback_role``, by default
    admin, monitor when the service runs with ``keys``."""
    try:
        address = parse_ads_endpoint(ads) if ads is not None else config.ads.address
    except ValueError as exc:
        _usage(f"bad --ads: {exc}")
    if net_id is not None:
        try:
            parse_net_id(net_id)
        except ValueError as exc:
            _usage(f"bad --ams-net-id: {exc}")
    if address is None:
        return None
    local = host_is_loopback(address[0])
    if not local and not config.ads.routes and not insecure:
        _usage(f"ADS address {address[0]}:{address[1]} is not a loopback address and [ads] "
               "has no routes: only loopback peers could be served; add [[ads.routes]] "
               "(docs/security.md), bind 127.0.0.1 (--ads 127.0.0.1), or --insecure")
    if config.ads.loopback_role is not None:
        loopback_role = Role.parse(config.ads.loopback_role)
    else:
        loopback_role = Role.MONITOR if keys else LOOPBACK_ROLE
    return AdsListen(address[0], address[1], net_id or config.ads.net_id, loopback_role,
                     open_to_all=insecure and not local and not config.ads.routes)


def _opcua_listen(config: ServiceConfig, opcua: str | None, keys: bool = False
                  ) -> OpcUaListen | None:
    """Where OPC UA listens: ``--opcua`` over the configuration's [opcua], with its
    security keys. Anonymous loopback sessions get ``[opcua] loopback_role``, by default
    admin, monitor when the service runs with ``keys`` or the server has a certificate;
    off loopback ``apply_security`` asks for a certificate and users (docs/opcua.md)."""
    try:
        address = parse_opcua_endpoint(opcua) if opcua is not None else config.opcua.address
    except ValueError as exc:
        _usage(f"bad --opcua: {exc}")
    if address is None:
        return None
    security: OpcUaSecurity = config.opcua
    if security.loopback_role is None and keys:
        security = security.model_copy(update={"loopback_role": Role.MONITOR.label})
    return OpcUaListen(address[0], address[1], security)


def _machine_config(path: Path | None, cycle_ms: float | None,
                    machine: EmbeddedMachine = EmbeddedMachine.THREE_AXIS) -> ServiceConfig:
    """The configuration file over the embedded machine, ``--cycle-ms`` over both."""
    try:
        config = load_config(path, machine)
        if cycle_ms is not None:
            config = ServiceConfig.model_validate({**config.model_dump(), "cycle_ms": cycle_ms})
    except ConfigError as exc:
        _usage(f"bad configuration:\n{exc}")
    except ValueError as exc:  # --cycle-ms out of range
        _usage(f"bad --cycle-ms: {exc}")
    return config


def _open_store(location: StoreLocation, config: ServiceConfig) -> ProgramStore:
    """The program store at ``location`` (created when absent), announced in the log."""
    try:
        store = ProgramStore(location.path, config.limits.program_max_bytes,
                             config.limits.program_max_files,
                             config.limits.store_max_total_bytes)
    except OSError as exc:
        _usage(f"cannot use program directory {location.path}: {exc.strerror}")
    log.info("program store: %s (%s)", store.root, location.source)
    removed = store.remove_unfinished_uploads()
    if removed:
        log.warning("program store: removed %d unfinished upload(s) a stopped service left",
                    removed)
    return store


def _open_outputs(
    output_dir: Path | None, config: ServiceConfig, store: StoreLocation
) -> OutputArea:
    """The output area (created when absent), announced in the log."""
    try:
        location = output_area_location(output_dir, config.output_dir, store)
    except ValueError as exc:
        _usage(str(exc))
    try:
        area = OutputArea(location.path)
    except OSError as exc:
        _usage(f"cannot use output directory {location.path}: {exc.strerror}")
    log.info("output area: %s (%s)", area.root, location.source)
    return area


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``cnc-service`` (``argv``: the options, default the command line)."""
    app(args=argv, prog_name="cnc-service")


if __name__ == "__main__":
    main()
