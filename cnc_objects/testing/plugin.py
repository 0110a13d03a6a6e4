"""The pytest plugin's fixtures, marker and report hook (registered by ``cnc_objects.testing``).

pytest imports this at every start, in every project where cnc-objects is installed:
only the standard library, pytest and ``.process`` are imported here; the client
library is imported inside the fixtures that use it.
"""

from __future__ import annotations

import importlib.util
from collections.abc import AsyncIterator, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from .process import ServiceProcess, start_service

if TYPE_CHECKING:
    from cnc_objects.clients import AsyncClient, Client

    from .alarms import AlarmRecorder
    from .trace import TraceRecorder

MARKER = "cnc_service"
MARKER_HELP = (
    "cnc_service(config=None, programs=(), args=()): how the cnc_service fixture starts "
    "its cnc-service: a TOML machine configuration and NC programs to upload (paths "
    "relative to the test file), further command-line options; ads=True serves ADS on a "
    "loopback address of its own (service.ads_address, service.ams_net_id)"
)
_OPTIONS = frozenset({"config", "programs", "args", "ads"})
CLIENT_TIMEOUT_S = 10.0  # per request; generous for a busy CI machine
LOG_LINES_ON_FAILURE = 200  # the end of the service's log shown with a failed test


def pytest_configure(config: pytest.Config) -> None:
    """Register the marker (so that ``--strict-markers`` accepts it)."""
    config.addinivalue_line("markers", MARKER_HELP)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Any:
    """A failed test that used a service shows the end of that service's log."""
    report = yield
    if report.failed:
        funcargs = getattr(item, "funcargs", {})
        for name, value in funcargs.items():
            if isinstance(value, ServiceProcess):
                lines = value.log[-LOG_LINES_ON_FAILURE:]
                report.sections.append((f"cnc-service log ({name}, {report.when})",
                                        "\n".join(lines)))
    return report


@pytest.fixture
def cnc_service(request: pytest.FixtureRequest,
                tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """A ``cnc-service`` of this test only: virtual clock, a free loopback port, an empty
    program store of its own, ADS off. ``@pytest.mark.cnc_service(config=...,
    programs=[...], args=[...], ads=True)`` on the test, its class or its module
    (``pytestmark``) configures it; the programs are uploaded over the wire before the
    test starts. At teardown the service is stopped; a service that does not exit with
    code 0 fails the test with its log."""
    config, programs, args = _marker_options(request)
    if "cnc_trace" in request.fixturenames and "--samples" not in args:
        args = [*args, "--samples", "repeatable"]  # the trace needs every sample
    marker = request.node.get_closest_marker(MARKER)
    ads = bool(marker.kwargs.get("ads", False)) if marker is not None else False
    service = start_service(*args, *(("--config", str(config)) if config else ()),
                            program_dir=tmp_path_factory.mktemp("cnc-programs"), ads=ads)
    try:
        if programs:
            _upload(service, programs)
        yield service
    finally:
        _stop(service)


@pytest.fixture(scope="session")
def cnc_shared_service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """One ``cnc-service`` for the whole session (default machine, virtual clock): for
    tests that only read, or put back what they change. To run every test of a directory
    on it, override ``cnc_service`` there: ``def cnc_service(cnc_shared_service): return
    cnc_shared_service``."""
    service = start_service(program_dir=tmp_path_factory.mktemp("cnc-programs-shared"))
    try:
        yield service
    finally:
        _stop(service)


@pytest.fixture
def cnc_client(cnc_service: ServiceProcess) -> Iterator[Client]:
    """A blocking ``Client`` connected to ``cnc_service``."""
    from cnc_objects.clients import Client

    with Client(cnc_service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
        yield client


@pytest.fixture
def cnc_alarms(cnc_client: Client) -> AlarmRecorder:
    """The alarms ``cnc_service`` raises during the test: ``raised_ids()``,
    ``active_ids()``, ``wait_for(id)``, ``clear()`` (``cnc_objects.testing.alarms``)."""
    from .alarms import AlarmRecorder

    return AlarmRecorder(cnc_client)


@pytest.fixture
def cnc_trace(cnc_service: ServiceProcess) -> TraceRecorder:
    """Records a program run's samples as (kernel time ns, object, value) rows:
    ``watch([...], cycle_ms=10, on_change=False)``, then ``run(program)``
    (``cnc_objects.testing.trace``). ``cnc_service`` then runs with ``--samples
    repeatable``; the marker's ``args`` may choose ``--clock virtual-step`` or ``step``."""
    from .trace import TraceRecorder

    return TraceRecorder(cnc_service.endpoint, stepping=_clock_of(cnc_service) == "step")


def _clock_of(service: ServiceProcess) -> str:
    """The clock a service was started on (the last ``--clock`` of its command line)."""
    argv = [str(a) for a in service.process.args]  # type: ignore[union-attr]
    clocks = [argv[k + 1] for k, arg in enumerate(argv[:-1]) if arg == "--clock"]
    return clocks[-1] if clocks else "realtime"


async def _async_client(cnc_service: ServiceProcess) -> AsyncIterator[AsyncClient]:
    """An ``AsyncClient`` connected to ``cnc_service``, on the test's event loop (needs
    pytest-asyncio)."""
    from cnc_objects.clients import AsyncClient

    async with AsyncClient(cnc_service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
        yield client


if importlib.util.find_spec("pytest_asyncio") is not None:
    import pytest_asyncio

    cnc_async_client = pytest_asyncio.fixture(_async_client, name="cnc_async_client",
                                              loop_scope="function")
else:  # without pytest-asyncio nothing can await it: say so instead of a puzzling error

    @pytest.fixture(name="cnc_async_client")
    def cnc_async_client() -> None:
        """Needs pytest-asyncio (``pip install pytest-asyncio``)."""
        pytest.fail("the cnc_async_client fixture needs pytest-asyncio: "
                    "pip install pytest-asyncio", pytrace=False)


def _marker_options(request: pytest.FixtureRequest) -> tuple[Path | None, list[Path], list[str]]:
    """(config file, program files, extra arguments) of the closest ``cnc_service``
    marker; relative paths are taken from the test file's directory."""
    marker = request.node.get_closest_marker(MARKER)
    if marker is None:
        return None, [], []
    where = f"@pytest.mark.{MARKER}"
    if marker.args:
        pytest.fail(f"{where} takes keyword options only ({', '.join(sorted(_OPTIONS))})",
                    pytrace=False)
    unknown = set(marker.kwargs) - _OPTIONS
    if unknown:
        pytest.fail(f"{where}: unknown option(s) {', '.join(sorted(unknown))}; it takes "
                    f"{', '.join(sorted(_OPTIONS))}", pytrace=False)
    base = request.path.parent
    config = marker.kwargs.get("config")
    programs = marker.kwargs.get("programs", ())
    args = marker.kwargs.get("args", ())
    if isinstance(programs, (str, Path)) or isinstance(args, str):
        pytest.fail(f"{where}: programs and args take a list", pytrace=False)
    config_path = base / config if config is not None else None
    program_paths = [base / p for p in programs]
    for path in ([config_path] if config_path else []) + program_paths:
        if not path.is_file():
            pytest.fail(f"{where}: no file {path}", pytrace=False)
    return config_path, program_paths, [str(a) for a in args]


def _upload(service: ServiceProcess, programs: list[Path]) -> None:
    """Upload ``programs`` into the service's store, each under its file name."""
    from cnc_objects.clients import Client

    names = [p.name for p in programs]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        pytest.fail(f"@pytest.mark.{MARKER}: two programs are named {', '.join(twice)}",
                    pytrace=False)
    with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
        for path in programs:
            client.upload(path.name, path.read_bytes())


def _stop(service: ServiceProcess) -> None:
    code = service.stop()
    if code != 0:
        pytest.fail(f"cnc-service exited with {code} (not 0):\n{service.log_text}",
                    pytrace=False)
