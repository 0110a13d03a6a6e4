"""``cnc-service``: the composition root. Builds kernel, address space and server, runs them.

    cnc-service [--config FILE] [--endpoint URL] [--clock realtime|virtual] [--speed X]
                [--cycle-ms MS] [--program-dir DIR] [--log-level L]

Logs the endpoint it listens on (``listening on tcp://...``); SIGINT and SIGTERM stop it
cleanly (sockets closed, cycle thread joined) with exit code 0. A bad configuration or
an endpoint that cannot be bound exits with code 2 and one line that says why.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import os
import signal
import sys
from pathlib import Path

import zmq

from .binding import build_address_space
from .config import ConfigError, MachineConfig, load_config
from .kernel.clock import Clock, RealtimeClock, VirtualClock
from .kernel.kernel import Kernel
from .program_service import ProgramStoreService
from .program_store import ProgramStore, StoreError
from .server import AdsServer
from .store_writer import StoreWriter

log = logging.getLogger("cnc-service")

DEFAULT_ENDPOINT = "tcp://127.0.0.1:5555"


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="cnc-service", description="CNC kernel serving its objects over ZeroMQ (ADS frames)."
    )
    p.add_argument("--config", type=Path, help="TOML machine configuration laid over the default")
    p.add_argument("--endpoint", default=DEFAULT_ENDPOINT, help="ZeroMQ endpoint to bind "
                   "(tcp://127.0.0.1:* picks a free port)")
    p.add_argument("--clock", choices=("realtime", "virtual"), default="realtime")
    p.add_argument("--speed", type=float, help="virtual clock: times real time (default: as fast "
                   "as the CPU allows while busy)")
    p.add_argument("--cycle-ms", type=float, help="cycle time in ms (overrides the configuration)")
    p.add_argument("--program-dir", type=Path, help="directory of the program store (default: "
                   "program_store_dir of the configuration, else "
                   "$XDG_DATA_HOME/cnc-objects/programs)")
    p.add_argument("--log-level", default="INFO",
                   choices=("DEBUG", "INFO", "WARNING", "ERROR"))
    return p


def make_clock(kind: str, cycle_s: float, speed: float | None) -> Clock:
    """The clock the cycle task runs on."""
    if kind == "realtime":
        return RealtimeClock(cycle_s)
    return VirtualClock(cycle_s, speed)


def program_dir(arg: Path | None, config: MachineConfig) -> Path:
    """Where the program store lives: the option, the configuration, the user's data dir."""
    if arg is not None:
        return arg
    if config.program_store_dir:
        return Path(config.program_store_dir).expanduser()
    data_home = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(data_home) / "cnc-objects" / "programs"


def _kernel_loader(store: ProgramStore):
    """The store as the kernel sees it: text by name, KeyError when absent."""

    def load(name: str) -> str:
        try:
            return store.read_text(name)
        except StoreError:
            raise KeyError(name) from None

    return load, store.exists


async def serve(
    config: MachineConfig, endpoint: str, clock_kind: str, speed: float | None, store: ProgramStore
) -> int:
    """Run kernel and server until SIGINT or SIGTERM."""
    loop = asyncio.get_running_loop()
    # The cycle thread must get the GIL soon after it wakes, even while the server is busy.
    sys.setswitchinterval(min(0.005, config.cycle_ms / 1000.0 / 4))
    load, exists = _kernel_loader(store)
    writer = StoreWriter(store)
    kernel = Kernel(
        config, make_clock(clock_kind, config.cycle_ms / 1000.0, speed), load, exists,
        writer.append,
    )
    space = build_address_space(kernel)
    try:
        server = AdsServer(
            space, kernel, endpoint, loop, programs=ProgramStoreService(store, writer.flush)
        )
    except zmq.ZMQError as exc:
        print(f"cnc-service: cannot listen on {endpoint}: {exc}", file=sys.stderr)
        return 2
    stop = asyncio.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    kernel.start()
    server.start()
    log.info(
        "listening on %s (machine %s, %d channels, %d objects, %s clock, cycle %g ms, "
        "programs in %s)",
        server.endpoint, config.name, len(config.channels), len(space), clock_kind,
        config.cycle_ms, store.root,
    )
    try:
        await stop.wait()
    finally:
        log.info("stopping")
        server.close()
        kernel.close()
        writer.close()
    log.info("stopped")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``cnc-service``; returns the exit code."""
    args = _parser().parse_args(argv)
    logging.basicConfig(
        level=args.log_level, format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        stream=sys.stderr,
    )
    if args.speed is not None and (args.clock != "virtual" or args.speed <= 0):
        print("cnc-service: --speed takes a positive factor and needs --clock virtual",
              file=sys.stderr)
        return 2
    try:
        config = load_config(args.config)
        if args.cycle_ms is not None:
            config = MachineConfig.model_validate({**config.model_dump(), "cycle_ms": args.cycle_ms})
    except ConfigError as exc:
        print(f"cnc-service: bad configuration:\n{exc}", file=sys.stderr)
        return 2
    except ValueError as exc:  # --cycle-ms out of range
        print(f"cnc-service: bad --cycle-ms: {exc}", file=sys.stderr)
        return 2
    directory = program_dir(args.program_dir, config)
    try:
        store = ProgramStore(directory)
    except OSError as exc:
        print(f"cnc-service: cannot use program directory {directory}: {exc.strerror}",
              file=sys.stderr)
        return 2
    return asyncio.run(serve(config, args.endpoint, args.clock, args.speed, store))


if __name__ == "__main__":
    sys.exit(main())
