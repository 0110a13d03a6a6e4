// cnc-web: the Program page: the program store (list, upload), the text of the program
// shown (a window of its lines), select / start / syntax check / dry run, and its tool
// path; in step with the channel's running program.

import { $, api, currentXY, el, facts, named, say, setText, sizeText, state, v, working } from "./core.js";
import { definePage } from "./router.js";
import { WINDOW_LEAD, fetchLines, goToLine, lines, showWindow, windowFirst } from "./program_lines.js";
import { clearLive, clearPlanned, drawPath, pathFrame, setPlanned } from "./toolpath.js";
import { takeUploads } from "./upload.js";

const PLAN_AUTO_MAX_BYTES = 2 << 20; // larger programs are planned on "Draw path" only

const shown = {
  sizes: {},        // program name -> size in bytes (the store's list)
  planning: null,   // the dry run under way (a Promise), awaited before a start
  following: false, // the running program is being opened
  followed: null,   // the run's program opened once (another may be looked at meanwhile)
};

async function loadPrograms() {
  const data = await api("GET", "/api/programs");
  const list = $("#program-list");
  shown.sizes = Object.fromEntries(data.programs.map((p) => [p.name, p.size_bytes]));
  list.replaceChildren(...data.programs.map((p) => {
    const item = el("li", { textContent: `${p.name}  (${sizeText(p.size_bytes)})` });
    item.dataset.name = p.name;
    item.classList.toggle("selected", p.name === state.program);
    item.addEventListener("click", () => showProgram(p.name));
    return item;
  }));
}

async function showProgram(name) {
  const part = await fetchLines(name, 1);
  state.program = name;
  clearPlanned();
  lines.checkErrors = {};
  lines.follow = true;
  if (!working()) clearLive();
  $("#program-name").textContent = name;
  for (const item of $("#program-list").children) item.classList.toggle("selected", item.dataset.name === name);
  showWindow(part);
  drawPath();
  if ((shown.sizes[name] ?? 0) > PLAN_AUTO_MAX_BYTES) {
    $("#path-note").textContent = "a large program: Draw path plans it (a dry run)";
    return;
  }
  await planShown(name);
}

// One dry run at a time in the channel: a plan waits for the one before it, and a
// program no longer shown is not planned at all.
function planShown(name) {
  const mine = (shown.planning || Promise.resolve()).then(() => (state.program === name ? loadPlanned(name) : undefined));
  shown.planning = mine;
  mine.finally(() => { if (shown.planning === mine) shown.planning = null; });
  return mine;
}

// The planned path is drawn as soon as a program is shown: a dry run in the channel
// (cnc-web keeps the last ones, so a program started from the page shows it while it runs).
async function loadPlanned(name) {
  $("#path-note").textContent = "planning…";
  try {
    const trace = await api("POST", `/api/channel/${state.channel}/trace`, { program: name, automatic: true }, true);
    if (state.program !== name) return;
    setPlanned(trace);
    $("#path-note").textContent = trace.ended === "READY" ? `planned ${trace.program_time_s.toFixed(3)} s`
      : `planned up to ${trace.ended} (Syntax check tells where)`;
  } catch (error) {
    if (state.program === name) $("#path-note").textContent = `no planned path: ${error.message}`;
  }
}

takeUploads(async (names) => {
  await loadPrograms();
  if (names.length) await showProgram(names[names.length - 1]);
});

async function needProgram() {
  if (!state.program) say("choose a program in the list first", true);
  if (shown.planning) await shown.planning;  // the channel is busy with the dry run until then
  return state.program;
}

$("#select-program").addEventListener("click", async () => {
  if (!await needProgram()) return;
  try {
    await api("POST", `/api/channel/${state.channel}/select`, { program: state.program });
    say(`channel ${state.channel}: ${state.program} selected`);
  } catch (_) { /* shown */ }
});

$("#start-program").addEventListener("click", async () => {
  if (!await needProgram()) return;
  try {
    await api("POST", `/api/channel/${state.channel}/select`, { program: state.program });
    clearLive();
    await api("POST", `/api/channel/${state.channel}/start`, {});
    say(`channel ${state.channel}: ${state.program} started`);
  } catch (_) { /* shown */ }
});

$("#check-program").addEventListener("click", async () => {
  if (!await needProgram()) return;
  try {
    say(`checking ${state.program}…`);
    const result = await api("POST", `/api/channel/${state.channel}/check`, { program: state.program });
    const found = result.errors.concat(result.aborted ? [result.aborted] : []);
    lines.checkErrors = {};
    for (const e of found) {
      if (e.file === state.program) lines.checkErrors[e.line] = `← error ${e.id} (${e.category}) col ${e.column}: ${e.message}`;
    }
    if (lines.window) showWindow(lines.window);  // the errors of the lines shown
    say(found.length ? `${state.program}: ${result.error_count} errors in ${result.lines} lines` : `${state.program}: no errors in ${result.lines} lines`, found.length > 0);
  } catch (_) { /* shown */ }
});

$("#draw-program").addEventListener("click", async () => {
  if (!await needProgram()) return;
  try {
    say(`dry run of ${state.program} (no axis moves)…`);
    const trace = await api("POST", `/api/channel/${state.channel}/trace`, { program: state.program });
    setPlanned(trace);
    say(`${state.program}: ${trace.program_time_s.toFixed(3)} s planned, ended ${trace.ended}`);
  } catch (_) { /* shown */ }
});

function renderProgramPage() {
  const c = `ch${state.channel}`;
  // in step with the channel: its running program is shown, opened while it runs too
  // (once per run: another program may be looked at meanwhile)
  const active = v(`${c}.mc_active_program_name_r`);
  if (!working()) shown.followed = null;
  const newRun = working() && active && active !== shown.followed;
  if (active && !shown.following && (!state.program || newRun)) {
    shown.following = true;
    if (working()) shown.followed = active;
    if (active === state.program) shown.following = false;
    else showProgram(active).catch(() => {}).finally(() => { shown.following = false; });
  }
  const here = currentXY(pathFrame().name.startsWith("workpiece") ? "pcs" : "acs");
  if (here) setText($("#position-line"), `X ${here[0].toFixed(4)}  Y ${here[1].toFixed(4)} mm`);
  setText($("#program-state"), named(facts.states, v(`${c}.mc_active_state_r`)));
  const block = v(`${c}.actual_block_number`);
  setText($("#program-block"), block === undefined || block < 0 ? "-" : `N${block} line ${v(`${c}.mc_active_line_r`)}`);
  const items = $("#program-text").children;
  const line = v(`${c}.mc_active_file_name_r`) === state.program ? v(`${c}.mc_active_line_r`) : null;
  const first = windowFirst();
  if (line !== lines.shownLine) {
    items[lines.shownLine - first]?.classList.remove("current");
    const item = items[line - first];
    if (item) {
      item.classList.add("current");
      item.scrollIntoView({ block: "nearest" });
    } else if (line > 0 && working() && lines.follow && !lines.loading && !shown.planning) {
      // the run left the window: the window follows it (not the page's own dry run that
      // plans the path: that one runs through the program while nobody started it)
      goToLine(line - WINDOW_LEAD);
    }
    lines.shownLine = item ? line : null;
  }
  drawPath();
}

definePage("program", { render: renderProgramPage, show: loadPrograms });
