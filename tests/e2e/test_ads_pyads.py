"""pyads, unmodified, against a real cnc-service over ADS (AMS/TCP).

pyads drives Beckhoff's AdsLib, which always dials port 48898 and picks the server by IP
address: the service gets a loopback address of its own (``127.0.0.<n>:48898``, see
``start_service(ads=True)``) so that services of parallel test runs never meet. One
module-scoped fixture opens pyads' port, sets the local AMS Net ID, adds the route and
opens a ``pyads.Connection`` per AMS port; they are closed together at the end (closing
one deletes the route the others use).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import pyads
import pytest

from cnc_objects.clients import Client
from cnc_objects.service import __version__
from cnc_objects.testing import ServiceProcess, run_program
from tests.support.pyads_plc import pyads_service

LOCAL_NET_ID = "127.0.0.1.1.20"  # this test process, as pyads' AMS router
CH1_COM, CH1_GEO = 0x120101, 0x121301
FEED_OVERRIDE_W = (CH1_COM, 0x09)  # ch1.mc_command_feed_override_w, UINT 0.1 %
FEED_OVERRIDE_R = (CH1_COM, 0x0A)  # ch1.mc_command_feed_override_r
LINK = "ch1.ax1.actual_link_to_physical_axis"  # UINT, 1 in the default machine
LENGTH = "gpCh[0].contour_lookahead.request.length"  # LREAL, read-write PLC symbol
START = "gpCh[0].contour_lookahead.request.start_position"  # LREAL, read-write
END_X = 40  # mm, the end of PROGRAM
# 0.02 mm blocks: every block end is a cycle the event-speed clock runs as a cycle (it
# runs the cruise between two in bulk), so that the run lasts long enough in wall time
# (2000 blocks to decode and plan) for a subscriber to see the axis on its way
PROGRAM = "G90 G1 F600\n" + "".join(
    f"X{k / 50:g}\n" for k in range(1, END_X * 50 + 1)) + "M30\n"
WAIT_S = 20.0


@dataclass
class Ads:
    """The service and one pyads connection per AMS port."""

    service: ServiceProcess
    plc: pyads.Connection  # 851
    geo: pyads.Connection  # 551
    com: pyads.Connection  # 553
    system: pyads.Connection  # 10000


@pytest.fixture(scope="module")
def ads(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Ads]:
    with pyads_service(tmp_path_factory.mktemp("ads-pyads"), LOCAL_NET_ID,
                       ports=(851, 551, 553, 10000)) as (service, connections):
        yield Ads(service, *connections)


def test_read_state(ads: Ads) -> None:
    assert ads.plc.read_state() == (pyads.ADSSTATE_RUN, 0)
    assert ads.system.read_state() == (pyads.ADSSTATE_RUN, 0)


def test_read_device_info(ads: Ads) -> None:
    name, version = ads.plc.read_device_info()
    assert name == "cnc-objects"
    assert f"{version.version}.{version.revision}.{version.build}" == __version__


def test_read_and_write_by_address_on_com(ads: Ads) -> None:
    ads.com.write(*FEED_OVERRIDE_W, 555, pyads.PLCTYPE_UINT)
    try:
        assert ads.com.read(*FEED_OVERRIDE_R, pyads.PLCTYPE_UINT) == 555
    finally:
        ads.com.write(*FEED_OVERRIDE_W, 1000, pyads.PLCTYPE_UINT)
    assert ads.com.read(*FEED_OVERRIDE_R, pyads.PLCTYPE_UINT) == 1000


def test_read_by_address_on_geo(ads: Ads) -> None:
    # ch1.ax1.actual_link_to_physical_axis (UINT): ch1 X drives physical axis 1.
    assert ads.geo.read(CH1_GEO, 0x10017, pyads.PLCTYPE_UINT) == 1
    assert ads.geo.read(CH1_GEO, 0x10018, pyads.PLCTYPE_UDINT) == 0  # link_state


def test_refusals_keep_the_connection(ads: Ads) -> None:
    with pytest.raises(pyads.ADSError) as wrong_size:
        ads.com.read(*FEED_OVERRIDE_R, pyads.PLCTYPE_UDINT)  # a UINT read as 4 bytes
    assert wrong_size.value.err_code == 0x705
    with pytest.raises(pyads.ADSError) as read_only:
        ads.com.write(*FEED_OVERRIDE_R, 10, pyads.PLCTYPE_UINT)
    assert read_only.value.err_code == 0x704
    with pytest.raises(pyads.ADSError) as no_group:
        ads.geo.read(0x777777, 0, pyads.PLCTYPE_UDINT)
    assert no_group.value.err_code == 0x702
    assert ads.com.read(*FEED_OVERRIDE_R, pyads.PLCTYPE_UINT) == 1000


def test_by_name_with_a_type(ads: Ads) -> None:
    ads.plc.write_by_name(LENGTH, 12.5, pyads.PLCTYPE_LREAL)
    assert ads.plc.read_by_name(LENGTH, pyads.PLCTYPE_LREAL) == 12.5
    # Every object by name, on every port: a GEO object through the PLC port and back.
    assert ads.plc.read_by_name(LINK, pyads.PLCTYPE_UINT) == 1
    assert ads.geo.read_by_name(LENGTH, pyads.PLCTYPE_LREAL) == 12.5


def test_by_name_without_a_type(ads: Ads) -> None:
    """pyads asks the symbol information (0xF009) for the type and the address."""
    ads.plc.write_by_name(LENGTH, 7.25)
    assert ads.plc.read_by_name(LENGTH) == 7.25
    assert ads.plc.read_by_name(LINK) == 1  # a GEO object seen from 851
    assert ads.plc.read_by_name("ch1.mc_command_feed_override_r") == 1000


def test_handles(ads: Ads) -> None:
    handle = ads.plc.get_handle(LENGTH)
    try:
        ads.plc.write_by_name("", 3.5, pyads.PLCTYPE_LREAL, handle=handle)
        assert ads.plc.read_by_name("", pyads.PLCTYPE_LREAL, handle=handle) == 3.5
        assert ads.plc.read(0xF005, handle, pyads.PLCTYPE_LREAL) == 3.5
    finally:
        ads.plc.release_handle(handle)
    link = ads.com.get_handle(LINK)  # handles work on every port
    assert ads.com.read_by_name("", pyads.PLCTYPE_UINT, handle=link) == 1
    ads.com.release_handle(link)


def test_sum_commands(ads: Ads) -> None:
    written = ads.plc.write_list_by_name({LENGTH: 4.5, START: 1.25})
    assert written == {LENGTH: "no error", START: "no error"}
    names = [LENGTH, START, LINK, "ch1.mc_command_feed_override_r"]
    assert ads.plc.read_list_by_name(names) == {
        LENGTH: 4.5, START: 1.25, LINK: 1, "ch1.mc_command_feed_override_r": 1000,
    }


def test_get_all_symbols(ads: Ads) -> None:
    symbols = {s.name: s for s in ads.plc.get_all_symbols()}
    with Client(ads.service.endpoint) as client:
        objects = client.browse()
    assert {info.name for info in objects} <= set(symbols)  # and the HLI's structs
    assert symbols["gpCh[0].contour_lookahead.request"].symbol_type == "HLI_CONTOUR_LOOKAHEAD_REQUEST"
    length = symbols[LENGTH]
    assert (length.symbol_type, length.index_group) == ("LREAL", 0x4020)
    assert symbols[LINK].symbol_type == "UINT"
    assert symbols[LINK].read() == 1  # through the symbol's own address


def test_an_unknown_symbol_is_0x710_and_the_connection_goes_on(ads: Ads) -> None:
    with pytest.raises(pyads.ADSError) as typed:
        ads.plc.read_by_name("no.such.symbol", pyads.PLCTYPE_INT)
    assert typed.value.err_code == 0x710
    with pytest.raises(pyads.ADSError) as untyped:
        ads.plc.read_by_name("no.such.symbol")
    assert untyped.value.err_code == 0x710
    assert ads.plc.read_state() == (pyads.ADSSTATE_RUN, 0)
    assert ads.plc.read_by_name(LINK, pyads.PLCTYPE_UINT) == 1


@dataclass
class Samples:
    """Values a notification callback received (on AdsLib's thread)."""

    values: list[Any] = field(default_factory=list)
    changed: threading.Condition = field(default_factory=threading.Condition)

    def add(self, value: Any) -> None:
        with self.changed:
            self.values.append(value)
            self.changed.notify_all()

    def wait_for(self, predicate: Any, what: str) -> None:
        with self.changed:
            if not self.changed.wait_for(lambda: predicate(self.values), WAIT_S):
                raise TimeoutError(f"no {what} within {WAIT_S} s; got {self.values[-5:]}")


def test_on_change_notifications_follow_a_running_program(ads: Ads) -> None:
    samples = Samples()

    @ads.plc.notification(pyads.PLCTYPE_DINT)
    def callback(handle: int, name: str, timestamp: Any, value: int) -> None:
        samples.add(value)

    attr = pyads.NotificationAttrib(4, pyads.ADSTRANS_SERVERONCHA, max_delay=0, cycle_time=1)
    handles = ads.plc.add_device_notification("ch1.ax1.command_position_acs", attr, callback)
    try:
        samples.wait_for(lambda v: len(v) >= 1, "first sample")
        with Client(ads.service.endpoint) as client:
            client.upload("ads.nc", PROGRAM.encode())
            run_program(client, "ads.nc", timeout_s=WAIT_S)
            end = client.read("ch1.ax1.command_position_acs")
        assert end == END_X * 10_000  # 0.1 um
        samples.wait_for(lambda v: v[-1] == end, "sample at the end position")
    finally:
        ads.plc.del_device_notification(*handles)
    values = samples.values
    assert len(set(values)) > 3, values  # the axis was seen moving
    assert values == sorted(values)  # X only moves forward here


def test_the_plc_state_can_be_watched(ads: Ads) -> None:
    samples = Samples()

    @ads.plc.notification(pyads.PLCTYPE_UINT)
    def callback(handle: int, name: str, timestamp: Any, value: int) -> None:
        samples.add(value)

    attr = pyads.NotificationAttrib(2, pyads.ADSTRANS_SERVERONCHA)
    handles = ads.plc.add_device_notification((0xF100, 0), attr, callback)
    try:
        samples.wait_for(lambda v: v == [pyads.ADSSTATE_RUN], "RUN")
        ads.plc.write_control(pyads.ADSSTATE_STOP, 0, 0, pyads.PLCTYPE_UINT)
        try:
            samples.wait_for(lambda v: v[-1] == pyads.ADSSTATE_STOP, "STOP")
            assert ads.plc.read_state() == (pyads.ADSSTATE_STOP, 0)
            assert ads.system.read_state() == (pyads.ADSSTATE_RUN, 0)
        finally:
            ads.plc.write_control(pyads.ADSSTATE_RUN, 0, 0, pyads.PLCTYPE_UINT)
        samples.wait_for(lambda v: v[-1] == pyads.ADSSTATE_RUN, "RUN again")
    finally:
        ads.plc.del_device_notification(*handles)
    assert ads.plc.read(0xF100, 0, pyads.PLCTYPE_UINT) == pyads.ADSSTATE_RUN


def test_strings_read_with_the_buffer_pyads_brings(ads: Ads) -> None:
    """pyads reads a STRING with 1024 characters (PLCTYPE_STRING), or with the length in
    the type name (STRING(83), one byte short of the buffer): both get the text."""
    name = "ch1.mc_active_program_name_r"
    with Client(ads.service.endpoint) as client:
        client.upload("named.nc", b"N10 G91 G1 X1 F6000\nN20 M30\n")
        run_program(client, "named.nc", timeout_s=WAIT_S)
        expected = client.read(name)
    assert expected != ""
    assert ads.plc.read_by_name(name, pyads.PLCTYPE_STRING) == expected
    assert ads.plc.read_by_name(name) == expected  # STRING(83) from the symbol information
    assert ads.com.read(CH1_COM, 0x3005, pyads.PLCTYPE_STRING) == expected


def test_a_plc_jogs_by_handwheel_and_reads_hb_display_r(ads: Ads) -> None:
    """Manual mode as a PLC plays it over ADS (docs/manual.md): the handwheel counter and
    the operation mode by name, ISG's ``hb_display_r`` symbols on port 851."""
    hb = "gpCh[0].bahn_state.coord_r[1].hb_display_r."
    with Client(ads.service.endpoint) as client:
        client.write("ch1.mc_command_reset_w", True)
        client.write("ch1.mc_command_mode_w", 4)  # MANUAL
    ads.plc.write_by_name("ch1.ax2.manual_operation_mode_w", 1, pyads.PLCTYPE_UINT)
    assert ads.plc.read_by_name(hb + "operation_mode", pyads.PLCTYPE_UINT) == 1
    assert ads.plc.read_by_name(hb + "state", pyads.PLCTYPE_UINT) == 2
    assert ads.plc.read_by_name(hb + "hr_aufloesung", pyads.PLCTYPE_DINT) == 10
    start = ads.plc.read_by_name("ch1.ax2.command_position_acs", pyads.PLCTYPE_DINT)
    counter = ads.plc.read_by_name("ch1.ax2.manual_handwheel_counter_w", pyads.PLCTYPE_DINT)
    ads.plc.write_by_name("ch1.ax2.manual_handwheel_counter_w", counter - 25,
                          pyads.PLCTYPE_DINT)
    deadline = time.monotonic() + WAIT_S
    while ads.plc.read_by_name("ch1.ax2.manual_moving_r", pyads.PLCTYPE_BOOL):
        assert time.monotonic() < deadline, "the handwheel motion did not end"
        time.sleep(0.01)
    assert ads.plc.read_by_name("ch1.ax2.command_position_acs",
                                pyads.PLCTYPE_DINT) == start - 250
    with pytest.raises(pyads.ADSError) as refused:  # 10 mm is the largest increment
        ads.plc.write_by_name("ch1.ax2.manual_increment_w", 100_001, pyads.PLCTYPE_UDINT)
    assert refused.value.err_code == 0x706
