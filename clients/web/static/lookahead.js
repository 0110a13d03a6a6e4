// cnc-web: the Look-ahead page: the contour look-ahead's elements (ahead, or the marked
// area of LOG ON) and the planned speed profile of a program (a dry run).

import { $, api, cells, el, facts, mm, named, say, state, v } from "./core.js";
import { definePage } from "./router.js";

async function lookahead(mode) {
  try {
    const data = await api("GET", `/api/channel/${state.channel}/lookahead?mode=${mode}`);
    $("#lookahead-state").textContent = `${data.count_logged_blocks} logged, log ${data.log_active ? "active" : "off"}, max_dist_prog_start ${mm(data.max_dist_prog_start)} mm`;
    const deg = (rad) => (rad * 180 / Math.PI).toFixed(3);
    $("#lookahead-table tbody").replaceChildren(...data.blocks.map((b, k) => {
      const row = el("tr");
      cells(row, [k, named(facts.contour_types, b.block_type), b.block_number, mm(b.start_position), mm(b.length),
        mm(b.programmed_radius), mm(b.compensated_radius), deg(b.circle_angle), deg(b.tangent_variation)]);
      return row;
    }));
    say(`channel ${state.channel}: ${data.blocks.length} look-ahead elements`);
  } catch (_) { /* shown */ }
}
$("#lookahead-ahead").addEventListener("click", () => lookahead("ahead"));
$("#lookahead-marked").addEventListener("click", () => lookahead("marked"));

$("#profile-draw").addEventListener("click", async () => {
  const program = state.program || v(`ch${state.channel}.mc_active_program_name_r`);
  if (!program) { say("choose a program on the program page first", true); return; }
  try {
    say(`planning ${program} (dry run, no axis moves)…`);
    const trace = await api("POST", `/api/channel/${state.channel}/trace`, { program });
    const s = trace.path_mm;
    const maxS = Math.max(...s, 1e-9);
    const maxV = Math.max(...trace.v_mm_s, ...trace.feed_limit_mm_s.filter((f) => f < 1e6), 1e-9);
    // over the run's cycles (time), so that the ramps keep their length on the chart
    const last = Math.max(s.length - 1, 1);
    const line = (values) => values.map((value, k) => `${(k / last * 600).toFixed(1)},${(200 - Math.min(value, maxV) / maxV * 190).toFixed(1)}`).join(" ");
    $("#profile-v").setAttribute("points", line(trace.v_mm_s));
    $("#profile-limit").setAttribute("points", line(trace.feed_limit_mm_s));
    $("#profile-name").textContent = program;
    $("#profile-max").textContent = `· over ${trace.program_time_s.toFixed(3)} s; top ${maxV.toFixed(1)} mm/s, path ${maxS.toFixed(1)} mm`;
    say(`${program}: planned ${trace.program_time_s.toFixed(3)} s`);
  } catch (_) { /* shown */ }
});

// nothing live: the page draws on request
definePage("lookahead", {});
