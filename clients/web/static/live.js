// cnc-web: the live values. One WebSocket (/ws): the page says which objects it watches,
// the server sends their newest values (one subscription per object for all browsers).
// Each message lands in state.values and queues one frame of the visible page.

import { say, state } from "./core.js";
import { queueRender } from "./router.js";

const listeners = {}; // object name -> [(value, before) => ...], called when it changes

// Call ``listener(value, before)`` whenever a message brings a value of ``name``.
export function onValue(name, listener) {
  (listeners[name] ||= []).push(listener);
}

function channelNames(ch) {
  const c = `ch${ch.id}`;
  const names = ["mc_active_mode_r", "mc_active_state_r", "mc_active_program_name_r", "actual_block_number",
    "mc_active_file_name_r", "mc_active_line_r", "mc_active_feedrate_r", "mc_active_feed_override_r",
    "mc_active_single_block_r", "mc_error_count_r", "mc_spindle_mode_r", "mc_spindle_active_rev_r",
    "mc_spindle_override_w", "mc_active_tool_r", "mc_active_tool_offset_r", "mc_active_zero_offset_r"]
    .map((leaf) => `${c}.${leaf}`);
  names.push(`gpCh[${ch.plc_index}].bahn_mc_control.suspend_axis_output.state_r`);
  for (const ax of ch.axes) {
    for (const leaf of ["command_position_acs", "command_position_pcs", "position_offset", "link_state",
      "homing_referenced_r", "manual_jog_plus_w", "manual_jog_minus_w"]) {
      names.push(`${c}.ax${ax.index}.${leaf}`);
    }
  }
  return names;
}

export function connectLive() {
  const url = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws`;
  const socket = new WebSocket(url);
  state.socket = socket;
  socket.addEventListener("open", () => {
    const names = state.machine.channels.flatMap(channelNames)
      .concat(["alarm_active_count_r", "alarm_raised_r"], state.objectWatch);
    socket.send(JSON.stringify({ watch: names }));
    say(`connected to ${state.session.endpoint}`);
  });
  socket.addEventListener("message", (event) => {
    const message = JSON.parse(event.data);
    state.stats.messages += 1;
    if (message.values) {
      const before = {};
      for (const name of Object.keys(message.values)) if (name in listeners) before[name] = state.values[name];
      Object.assign(state.values, message.values);
      if (Object.keys(message.values).some((n) => n.endsWith("command_position_acs"))) state.stats.positionUpdates += 1;
      for (const [name, was] of Object.entries(before)) {
        for (const listener of listeners[name]) listener(state.values[name], was);
      }
    }
    if (message.errors) Object.assign(state.watchErrors, message.errors);
    queueRender();
  });
  socket.addEventListener("close", () => {
    say("live values lost: reconnecting…", true);
    setTimeout(connectLive, 1000);
  });
}

export function watch(names) {
  if (state.socket && state.socket.readyState === WebSocket.OPEN) state.socket.send(JSON.stringify({ watch: names }));
}

export function unwatch(names) {
  if (state.socket && state.socket.readyState === WebSocket.OPEN) state.socket.send(JSON.stringify({ unwatch: names }));
}
