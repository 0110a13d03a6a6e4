"""Helical interpolation (issue 39) through a real service: G3 with Z in G17.

The helix of these programs: centre (0, 0), radius 10, from (10, 0, 0) half a turn
counter-clockwise to (-10, 0, -6); at the angle phi travelled Z = -6 * phi / pi, and its
length is sqrt((10 * pi)^2 + 6^2) mm.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from cnc_objects.clients import ChannelError, Client
from cnc_objects.testing import ServiceProcess, run_program, serving, wait_for
from tests.support.service import reset_client

HELIX_MM = math.hypot(10.0 * math.pi, 6.0)
HELIX = "N10 G0 X10 Y0 Z0\nN20 G17 G3 X-10 Y0 Z-6 I-10 J0 F{feed}\nN30 M30\n"


@pytest.fixture(scope="module")
def machine() -> Iterator[ServiceProcess]:
    with serving() as service:
        yield service


@pytest.fixture
def c(machine: ServiceProcess) -> Iterator[Client]:
    with reset_client(machine) as client:
        yield client


def test_helix_runs_to_its_end_with_the_helix_length(c: Client) -> None:
    c.upload("helix.nc", HELIX.format(feed=600).encode())
    s = run_program(c, "helix.nc", timeout_s=30)
    assert s.state == "READY"
    assert s.positions_mm == pytest.approx({"X": -10.0, "Y": 0.0, "Z": -6.0}, abs=1e-9)
    values = c.read_many(["ch1.dist_prog_start", "ch1.program_time"])
    # the path distance (0.1 um): the rapid move plus the length along the helix
    assert values["ch1.dist_prog_start"] == pytest.approx((10.0 + HELIX_MM) * 10_000, abs=2)
    assert values["ch1.program_time"] >= HELIX_MM / 10.0  # F600 = 10 mm/s


def test_held_helix_stands_on_the_helix(c: Client) -> None:
    # F1: the helix takes half an hour of machining, the HOLD written after START
    # arrives within it (the event-speed clock would pass a short move first)
    c.mdi("G0 X10 Y0 Z0")
    c.wait_program(1, timeout_s=30)
    c.upload("slow_helix.nc", b"N20 G17 G3 X-10 Y0 Z-6 I-10 J0 F1\nN30 M30\n")
    c.run_program("slow_helix.nc")
    c.hold(1)
    wait_for(c, "ch1.actual_path_velocity", 0.0)
    # the objects give whole 0.1 um: a rounding of up to 0.05 um per axis
    x, y, z = (c.read(f"ch1.ax{k}.command_position_acs") / 10_000.0 for k in (1, 2, 3))
    assert math.hypot(x, y) == pytest.approx(10.0, abs=1e-4)
    phi = math.atan2(y, x) % (2.0 * math.pi)  # ccw from +X, within the half turn
    assert 0.0 < phi < math.pi and z < 0.0  # moved, and not to the end
    assert z == pytest.approx(-6.0 * phi / math.pi, abs=1e-4)
    c.reset(1)


def test_helix_end_off_the_circle_is_the_plane_arcs_error(c: Client) -> None:
    ids = []
    for name, z_word in (("plane_bad.nc", ""), ("helix_bad.nc", " Z-5")):
        c.reset(1)
        c.upload(name, f"G0 X10 Y0 Z0\nG3 X0 Y10.5{z_word} I-10 J0 F600\nM30\n".encode())
        c.run_program(name)
        with pytest.raises(ChannelError):
            c.wait_program(1, timeout_s=30)
        ids.append(c.read("ch1.mc_error_1_id_r"))
    assert ids[0] == ids[1] == 21758  # ARC_RADIUS_DIFFERENCE, as for the plane arc


def test_the_dry_run_trace_cnc_web_draws_carries_the_helix_z(c: Client) -> None:
    # the tool path of cnc-web's program page is this trace (/api/.../trace): every
    # sample of the helix block stands on the helix, Z with the angle
    c.mdi("G0 X0 Y0 Z0")  # the rapid move to the helix start is 10 mm
    c.wait_program(1, timeout_s=30)
    c.upload("trace_helix.nc", HELIX.format(feed=600).encode())
    run = c.trace_run("trace_helix.nc", 1, timeout_s=30)
    c.reset(1)
    assert run.ended == "READY"
    xs, ys, zs = (run.positions_mm[a] for a in "XYZ")
    on_helix = [(x, y, z) for x, y, z in zip(xs, ys, zs) if z < 0.0]
    assert len(on_helix) > 100
    for x, y, z in on_helix:
        assert math.hypot(x, y) == pytest.approx(10.0, abs=1e-6)
        phi = math.atan2(y, x) % (2.0 * math.pi)
        phi = math.pi if z == pytest.approx(-6.0) else phi  # the end: -pi folds
        assert z == pytest.approx(-6.0 * phi / math.pi, abs=1e-6)
    assert run.path_mm[-1] == pytest.approx(10.0 + HELIX_MM, abs=1e-6)
