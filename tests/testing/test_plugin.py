"""The pytest plugin (``cnc_objects.testing``): its fixtures, marker and failure reports.

Tests that must see a test fail (a service that does not exit 0, a bad marker) run
pytest on a small test file of their own (``pytester``) and read its outcome.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from cnc_objects.clients import AsyncClient, Client
from cnc_objects.testing import ServiceProcess


def test_a_service_of_its_own_with_an_empty_store(cnc_service: ServiceProcess,
                                                   cnc_client: Client) -> None:
    assert cnc_service.endpoint.startswith("tcp://127.0.0.1:")
    assert cnc_service.process.poll() is None
    assert cnc_client.endpoint == cnc_service.endpoint
    assert cnc_client.programs() == []
    assert any("virtual clock" in line for line in cnc_service.log)


@pytest.mark.cnc_service(config="data/one-channel.toml", programs=["data/short.nc"],
                         args=["--cycle-ms", "2"])
def test_the_marker_gives_configuration_programs_and_options(cnc_client: Client) -> None:
    assert cnc_client.read("cnc_number_of_channel_r") == 1  # the default machine has 2
    assert [p.name for p in cnc_client.programs()] == ["short.nc"]
    assert cnc_client.download("short.nc") == b"N10 G1 X10 Y5 F6000\nN20 M30\n"
    assert cnc_client.read("cnc_cycle_time_r") == 2000  # us


async def test_async_client_on_the_tests_event_loop(cnc_async_client: AsyncClient) -> None:
    await cnc_async_client.write("ch1.mc_command_feed_override_w", 250)
    assert await cnc_async_client.read("ch1.mc_active_feed_override_r") == 250


def test_the_plugin_imports_no_client_library() -> None:
    """pytest imports the plugin in every project that has cnc-objects installed: it
    must not pull in ZeroMQ, msgpack or the kernel until a test uses them."""
    code = ("import sys, cnc_objects.testing\n"
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
            "{'zmq', 'msgpack', 'numpy', 'pydantic'} or m.startswith('cnc_objects.clients')"
            " or m.startswith('cnc_objects.service'))\n"
            "print(heavy)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60, check=True)
    assert done.stdout.strip() == "[]"


# --------------------------------------------------------------------- outcomes seen from outside


def run_inner(pytester: pytest.Pytester, source: str, **files: str) -> pytest.RunResult:
    """Run pytest on ``source`` (as test_inner.py, beside ``files``) in a directory of
    its own; the plugin comes from its entry point, as in a user's project."""
    pytester.makeini("[pytest]\nasyncio_default_fixture_loop_scope = function\n")
    pytester.makepyfile(test_inner=source)
    for name, text in files.items():
        (pytester.path / name).write_text(text)
    return pytester.runpytest_inprocess("-p", "no:cacheprovider")


def test_a_service_that_does_not_exit_0_fails_the_test_with_its_log(
    pytester: pytest.Pytester,
) -> None:
    result = run_inner(pytester, """
        import signal

        def test_kill(cnc_service):
            cnc_service.process.send_signal(signal.SIGKILL)
            cnc_service.process.wait(10)
    """)
    result.assert_outcomes(passed=1, errors=1)
    result.stdout.fnmatch_lines(["*cnc-service exited with -9 (not 0)*",
                                 "*listening on tcp://127.0.0.1:*"])


def test_a_failed_test_shows_the_services_log(pytester: pytest.Pytester) -> None:
    result = run_inner(pytester, """
        def test_fails(cnc_client):
            cnc_client.upload("a.nc", b"M30\\n")
            assert False
    """)
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*cnc-service log (cnc_service, call)*",
                                 "*program 'a.nc' uploaded*"])


@pytest.mark.parametrize(("marker", "message"), [
    ('config="nothing.toml"', "@pytest.mark.cnc_service: no file */nothing.toml"),
    ('programs=["p.nc", "sub/p.nc"]', "@pytest.mark.cnc_service: two programs are named p.nc"),
    ('program=["p.nc"]', "@pytest.mark.cnc_service: unknown option(s) program; it takes *"),
    ('programs="p.nc"', "@pytest.mark.cnc_service: programs and args take a list"),
    ('"p.nc"', "@pytest.mark.cnc_service takes keyword options only*"),
])
def test_a_bad_marker_is_named(pytester: pytest.Pytester, marker: str, message: str) -> None:
    (pytester.path / "sub").mkdir()
    (pytester.path / "sub" / "p.nc").write_text("M30\n")
    result = run_inner(pytester, f"""
        import pytest

        @pytest.mark.cnc_service({marker})
        def test_marked(cnc_service):
            pass
    """, **{"p.nc": "M30\n"})
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines([f"*{message}*"])


def test_a_bad_configuration_fails_the_setup_with_the_services_words(
    pytester: pytest.Pytester,
) -> None:
    result = run_inner(pytester, """
        import pytest

        @pytest.mark.cnc_service(config="machine.toml")
        def test_marked(cnc_service):
            pass
    """, **{"machine.toml": "cycle_ms = -1\n"})
    result.assert_outcomes(errors=1)
    result.stdout.fnmatch_lines(["*cnc-service exited with 2 before listening*",
                                 "*cycle_ms: Input should be greater than 0.05*"])


def test_the_marker_is_registered(pytester: pytest.Pytester) -> None:
    pytester.makeini("[pytest]\nasyncio_default_fixture_loop_scope = function\n")
    result = pytester.runpytest_inprocess("--markers")
    result.stdout.fnmatch_lines(["@pytest.mark.cnc_service(config=None, programs=(), args=())*"])


def test_a_module_can_run_on_the_shared_service(pytester: pytest.Pytester) -> None:
    """Overriding ``cnc_service`` with ``cnc_shared_service`` (docs/testing.md): both
    tests see one process, and the first test's write."""
    result = run_inner(pytester, """
        import pytest

        @pytest.fixture
        def cnc_service(cnc_shared_service):
            return cnc_shared_service

        def test_first(cnc_client):
            cnc_client.write("ch1.mc_command_feed_override_w", 123)

        def test_second(cnc_client):
            assert cnc_client.read("ch1.mc_active_feed_override_r") == 123
    """)
    result.assert_outcomes(passed=2)
