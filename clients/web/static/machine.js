// cnc-web: the Machine page: every channel's state and every axis's positions, the
// channel commands (start, hold, reset) and the feed and spindle override sliders.

import { $, api, cells, facts, mm, named, raw, referenced, rowFor, say, scaled, scaleOf, state, v } from "./core.js";
import { definePage } from "./router.js";

const fixed = (value, digits) => (value === undefined ? "-" : value.toFixed(digits));

function renderMachine() {
  const m = state.machine;
  const channels = $("#channels tbody");
  const axes = $("#axes tbody");
  for (const ch of m.channels) {
    const c = `ch${ch.id}`;
    const line = v(`${c}.mc_active_line_r`);
    const block = v(`${c}.actual_block_number`);
    const override = scaled(`${c}.mc_active_feed_override_r`);
    cells(rowFor(channels, c), [
      ch.id, named(facts.modes, v(`${c}.mc_active_mode_r`)), named(facts.states, v(`${c}.mc_active_state_r`)),
      v(`${c}.mc_active_program_name_r`) || "-",
      block === undefined || block < 0 ? "-" : `N${block} ${v(`${c}.mc_active_file_name_r`) || ""}:${line ?? ""}`,
      fixed(scaled(`${c}.mc_active_feedrate_r`), 1),
      override === undefined ? "-" : `${override.toFixed(1)} ${scaleOf(`${c}.mc_active_feed_override_r`).unit}`,
      v(`${c}.mc_active_single_block_r`) ? "on" : "off",
      v(`gpCh[${ch.plc_index}].bahn_mc_control.suspend_axis_output.state_r`) ? "suspended" : "active",
      named(facts.spindle_modes, v(`${c}.mc_spindle_mode_r`)),
      fixed(scaled(`${c}.mc_spindle_active_rev_r`), 0),
      v(`${c}.mc_active_tool_r`) === undefined ? "-" : `T${v(`${c}.mc_active_tool_r`)} D${v(`${c}.mc_active_tool_offset_r`) ?? "-"} G${53 + (v(`${c}.mc_active_zero_offset_r`) || 0)}`,
      v(`${c}.mc_error_count_r`) ?? "-",
    ]);
    for (const ax of ch.axes) {
      const a = `${c}.ax${ax.index}`;
      cells(rowFor(axes, a), [
        `${c} ${ax.name}${ax.unit === "°" ? " (°)" : ""}`, mm(v(`${a}.command_position_acs`)), mm(v(`${a}.command_position_pcs`)),
        mm(v(`${a}.position_offset`)), named(facts.link_states, v(`${a}.link_state`)), ax.drive || "-",
        referenced(v(`${a}.homing_referenced_r`)),
      ]);
    }
  }
  const c = `ch${state.channel}`;
  showSlider($("#override"), $("#override-value"), `${c}.mc_active_feed_override_r`);
  showSlider($("#spindle-override"), $("#spindle-override-value"), `${c}.mc_spindle_override_w`);
}

// a slider shows the object's value in % (not while the operator moves it)
function showSlider(slider, output, name) {
  const value = scaled(name);
  if (value === undefined || document.activeElement === slider) return;
  const text = String(Math.round(value));
  if (slider.value !== text) slider.value = text;
  if (output.textContent !== text) output.textContent = text;
}

for (const button of document.querySelectorAll("[data-command]")) {
  button.addEventListener("click", () => command(button.dataset.command));
}

async function command(what) {
  try {
    await api("POST", `/api/channel/${state.channel}/${what}`, {});
    say(`channel ${state.channel}: ${what}`);
  } catch (_) { /* shown */ }
}

function overrideSlider(input, output, object) {
  input.addEventListener("input", () => { output.textContent = input.value; });
  input.addEventListener("change", async () => {
    const name = `ch${state.channel}.${object}`;
    const value = raw(name, Number(input.value));
    try {
      await api("POST", "/api/write", { name, value });
      say(`${name} := ${value}`);
    } catch (_) { /* shown */ }
    input.blur();
  });
}
overrideSlider($("#override"), $("#override-value"), "mc_command_feed_override_w");
overrideSlider($("#spindle-override"), $("#spindle-override-value"), "mc_spindle_override_w");

definePage("machine", { render: renderMachine });
