"""Syntax check over the wire: the execution mode by address (logical and index-based),
the PLC control unit and display flags on port 851, syn_chk objects, the log download."""

from __future__ import annotations

import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.protocol.constants import CncPort
from cnc_objects.testing import run_program, wait_for

PROGRAM = b"N10 G1 X10 F1000\nN20 G1 Q5 X20\nN30 G00 G01 X0\nM30\n"


def test_mode_objects_plc_unit_flags_and_log_over_the_wire(cnc_client: Client) -> None:
    api = cnc_client
    com = CncPort.COM
    # the execution mode by address: logical group 0x120101 and index-based 0x20101
    api.write_address(com, 0x20101, 0x3F, "SGN32", 0x8)
    assert api.read_address(com, 0x120101, 0x40, "SGN32") == 0x8
    assert api.read("gpCh[0].decoder_mc_control.execution_mode.request_r") == 0x8
    with pytest.raises(AdsError) as refused:
        api.write("gpCh[0].decoder_mc_control.execution_mode.command_w", 0x100)
    assert refused.value.code == 0x706 and "KIN_TRAFO_OFF" in str(refused.value)
    with pytest.raises(AdsError) as read_only:
        api.write("gpCh[0].decoder_mc_control.execution_mode.state_r", 0x8)
    assert read_only.value.code == 0x704
    api.write("ch1.syn_chk.record_result", True)
    api.write("ch1.syn_chk.interactive", True)
    assert api.read("ch1.syn_chk.errors_total") == 0
    api.upload("prog.nc", PROGRAM)
    api.run_program("prog.nc")
    # interactive: HOLD after the error in line 2, with the PLC flags
    wait_for(api, "ch1.mc_active_state_r", 5)  # HOLD
    assert api.read("pMC[0].StateDecoder_Data.X_SyntaxCheck") is True
    assert api.read("pMC[0].StateDecoder_Data.X_WaitAfterError") is True
    assert api.read("pMC[0].StateDecoder_Data.X_WaitContinue") is False
    assert api.read("ch1.mc_active_line_r") == 2
    assert api.read("ch1.mc_active_file_name_r") == "prog.nc"
    assert api.read("ch1.mc_active_file_offset_r") == len(b"N10 G1 X10 F1000\n")
    assert api.read("ch1.mc_active_execution_mode_r") == 0x2048
    api.write("ch1.mc_command_start_w", True)  # go on after the error
    wait_for(api, "ch1.mc_active_line_r", 3)
    wait_for(api, "ch1.mc_active_state_r", 5)  # HOLD again, after the error in line 3
    assert api.read("ch1.mc_active_line_r") == 3
    api.write("ch1.mc_command_start_w", True)
    api.wait_program(timeout_s=30)
    assert api.read("pMC[0].StateDecoder_Data.X_SyntaxCheck") is False
    assert [api.read(f"ch1.mc_error_{k}_id_r") for k in (1, 2, 3)] == [21309, 21220, 20121]
    log = api.download_output("dec01.sc").decode()
    assert "error 21220 (term) at prog.nc:2:8: " in log
    assert "error 20121 (combination) at prog.nc:3:9: " in log
    assert log.rstrip().endswith("; end: 4 lines, 4 blocks, 2 errors, complete")
    assert api.read("ax1.command_position_acs") == 0  # nothing moved


@pytest.mark.cnc_service(args=["--clock", "realtime"])
def test_prod_time_on_the_realtime_clock_waits_for_a_slow_decoder(cnc_client: Client) -> None:
    """A computation before the motion must not count as machining time: the calculation
    waits for the decoder and gives the virtual-clock run's time exactly."""
    from cnc_objects.service.kernel.commands import SetExecutionMode
    from tests.support.kernel import KernelHarness

    program = ("#VAR\nV.L.I = 0\n#ENDVAR\n$WHILE V.L.I < 20000\nV.L.I = V.L.I + 1\n$ENDWHILE\n"
               "G1 X10 F6000\nG2 X20 I5 J0\nG1 X0\nM30\n")
    with KernelHarness() as harness:
        expected = harness.run(program, "p.nc").channel.path.program_time_s
        assert harness.command(SetExecutionMode(0, 0x10)) is None
        # the same cycles; their sum may round in its last bit otherwise when the
        # calculation waited for the decoder (seen under parallel load: 0.508 against
        # 0.5079999999999999), so a nanosecond's tolerance, far below one 1 ms cycle
        assert harness.run(program, "p.nc").channel.path.program_time_s == pytest.approx(
            expected, abs=1e-9)
    api = cnc_client
    api.upload("p.nc", program.encode())
    api.write("ch1.mc_command_execution_mode_w", 0x10)
    status = run_program(api, "p.nc", timeout_s=60)
    assert status.program_time_s == pytest.approx(expected, abs=1e-9)
    assert api.read("ax1.command_position_acs") == 0
