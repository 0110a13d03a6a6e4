// cnc-web: the browser side. Plain JavaScript, no build step, no library, no CDN.
// Live values come over one WebSocket (/ws): the page says which objects it watches,
// the server sends their newest values (one subscription per object for all browsers).
// Every write goes through the JSON API with the session's CSRF token; a refusal is
// shown on the message line in the service's words.
"use strict";

const UM01_PER_MM = 10000; // positions are in 0.1 um
const SPINDLE_MODES = { 1: "M5", 2: "M3", 4: "M4", 8: "M19" };
const LINK_STATES = { 0: "linked", 1: "requested", 2: "waiting ack" };
const CONTOUR_TYPES = { 1: "linear", 2: "circular", 3: "LOG ON", 4: "LOG PARAM", 5: "LOG OFF", 6: "polynomial" }; // ContourBlockType
const PAGES = ["machine", "program", "mdi", "tools", "lookahead", "alarms", "objects"];
const WORKING_STATES = ["ACTIVE", "HOLD"];
const MDI_HISTORY_KEY = "cnc-web-mdi-history";
const MDI_HISTORY_MAX = 30;

const state = {
  session: null,
  machine: null,
  channel: 1,
  values: {},          // object name -> newest value
  watchErrors: {},     // object name -> why it cannot be watched
  socket: null,
  program: null,       // the program shown on the program page
  programLines: [],
  planned: null,       // {x: [], y: []} of the planned tool path (machine coordinates)
  planning: null,      // the dry run under way (a Promise), awaited before a start
  live: [],            // [x, y] machine positions of the tool while a program runs
  extent: null,        // [minX, minY, maxX, maxY] of the tool path view: grows, never shrinks
  page: "machine",
  objectWatch: [],     // names on the objects page's watch list
  renderQueued: false,
  stats: { messages: 0, positionUpdates: 0, since: performance.now() },
};
window.cncStats = state.stats; // read by the tests and the benchmark

const $ = (sel) => document.querySelector(sel);
const el = (tag, props = {}, ...children) => {
  const node = Object.assign(document.createElement(tag), props);
  for (const child of children) node.append(child);
  return node;
};

// ------------------------------------------------------------------ message line

function say(text, isError = false) {
  const line = $("#message");
  line.textContent = text;
  line.classList.toggle("error", isError);
}

// ------------------------------------------------------------------ API

async function api(method, path, body, quiet = false) {
  const headers = {};
  if (state.session && state.session.csrf) headers["X-CSRF-Token"] = state.session.csrf;
  let payload = body;
  if (body !== undefined && !(body instanceof FormData)) {
    headers["Content-Type"] = "application/json";
    payload = JSON.stringify(body);
  }
  const response = await fetch(path, { method, headers, body: payload, credentials: "same-origin" });
  let data = {};
  try { data = await response.json(); } catch (_) { data = {}; }
  if (!response.ok) {
    const why = data.error || `${response.status} ${response.statusText}`;
    if (!quiet) say(why, true);
    if (response.status === 401 && state.session && state.session.sign_in_required) showLogin();
    throw new Error(why);
  }
  return data;
}

// ------------------------------------------------------------------ session and sign-in

async function loadSession() {
  state.session = await api("GET", "/api/session");
  const s = state.session;
  $("#who").textContent = s.role ? `${s.role} · ${s.endpoint}` : "";
  $("#logout").hidden = !(s.sign_in_required && s.role);
  for (const control of document.querySelectorAll(".write")) control.disabled = !s.may_write;
  $("#upload-input").disabled = !s.may_upload;  // the program store: admin, as on the service
  return s;
}

function showLogin() {
  for (const page of document.querySelectorAll(".page")) page.hidden = true;
  const roles = $("#login-role");
  roles.replaceChildren(...(state.session ? state.session.roles : []).map((r) => el("option", { value: r, textContent: r })));
  $("#login").hidden = false;
  say("sign in with a role's password");
}

$("#login-form").addEventListener("submit", async (event) => {
  event.preventDefault();
  try {
    await api("POST", "/api/login", { role: $("#login-role").value, password: $("#login-password").value });
    $("#login-password").value = "";
    $("#login").hidden = true;
    await start();
  } catch (_) { /* shown on the message line */ }
});

$("#logout").addEventListener("click", async () => {
  await api("POST", "/api/logout", {});
  if (state.socket) state.socket.close();
  location.reload();
});

// ------------------------------------------------------------------ live values

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

function connectLive() {
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
      const before = state.values["alarm_raised_r"];
      Object.assign(state.values, message.values);
      if (Object.keys(message.values).some((n) => n.endsWith("command_position_acs"))) state.stats.positionUpdates += 1;
      if (before !== undefined && state.values["alarm_raised_r"] > before) showNewestAlarm();
    }
    if (message.errors) Object.assign(state.watchErrors, message.errors);
    queueRender();
  });
  socket.addEventListener("close", () => {
    say("live values lost: reconnecting…", true);
    setTimeout(connectLive, 1000);
  });
}

function watch(names) {
  if (state.socket && state.socket.readyState === WebSocket.OPEN) state.socket.send(JSON.stringify({ watch: names }));
}

function unwatch(names) {
  if (state.socket && state.socket.readyState === WebSocket.OPEN) state.socket.send(JSON.stringify({ unwatch: names }));
}

function queueRender() {
  if (state.renderQueued) return;
  state.renderQueued = true;
  requestAnimationFrame(() => {
    state.renderQueued = false;
    render();
  });
}

const v = (name) => state.values[name];
const mm = (value) => (value === undefined ? "-" : (value / UM01_PER_MM).toFixed(4));
const named = (table, value) => (value === undefined ? "-" : (table[value] || String(value)));
const referenced = (value) => (value === undefined ? "-" : (value ? "yes" : "no"));

// ------------------------------------------------------------------ rendering

// Only the visible page is drawn: a frame costs what one page costs, not all of them.
const RENDERERS = { machine: () => renderMachine(), program: () => renderProgramPage(), mdi: () => renderJog(), objects: () => renderWatch() };

function render() {
  recordLivePath();  // the path so far is kept whatever page is shown
  const renderer = RENDERERS[state.page];
  if (renderer) renderer();
  const active = v("alarm_active_count_r") || 0;  // the service's active alarm list
  $("#alarm-count").textContent = active ? String(active) : "";
}

function cells(row, values) {
  if (row.children.length !== values.length) row.replaceChildren(...values.map(() => el("td")));
  values.forEach((value, k) => {
    const cell = row.children[k];
    const text = String(value);
    if (cell.textContent !== text) cell.textContent = text;
    if (typeof value === "string" && /^-?\d+\.\d+$/.test(value)) cell.className = "num";
  });
}

function rowFor(tbody, key) {
  let row = tbody.querySelector(`tr[data-key="${CSS.escape(key)}"]`);
  if (!row) {
    row = el("tr");
    row.dataset.key = key;
    tbody.append(row);
  }
  return row;
}

function renderMachine() {
  const m = state.machine;
  const channels = $("#channels tbody");
  const axes = $("#axes tbody");
  for (const ch of m.channels) {
    const c = `ch${ch.id}`;
    const line = v(`${c}.mc_active_line_r`);
    const block = v(`${c}.actual_block_number`);
    const feed = v(`${c}.mc_active_feedrate_r`);
    const rev = v(`${c}.mc_spindle_active_rev_r`);
    cells(rowFor(channels, c), [
      ch.id, named(m.modes, v(`${c}.mc_active_mode_r`)), named(m.states, v(`${c}.mc_active_state_r`)),
      v(`${c}.mc_active_program_name_r`) || "-",
      block === undefined || block < 0 ? "-" : `N${block} ${v(`${c}.mc_active_file_name_r`) || ""}:${line ?? ""}`,
      feed === undefined ? "-" : (feed * 60 / 1000).toFixed(1),
      v(`${c}.mc_active_feed_override_r`) === undefined ? "-" : `${(v(`${c}.mc_active_feed_override_r`) / 10).toFixed(1)} %`,
      v(`${c}.mc_active_single_block_r`) ? "on" : "off",
      v(`gpCh[${ch.plc_index}].bahn_mc_control.suspend_axis_output.state_r`) ? "suspended" : "active",
      named(SPINDLE_MODES, v(`${c}.mc_spindle_mode_r`)),
      rev === undefined ? "-" : (rev / 6000).toFixed(0),
      v(`${c}.mc_active_tool_r`) === undefined ? "-" : `T${v(`${c}.mc_active_tool_r`)} D${v(`${c}.mc_active_tool_offset_r`) ?? "-"} G${53 + (v(`${c}.mc_active_zero_offset_r`) || 0)}`,
      v(`${c}.mc_error_count_r`) ?? "-",
    ]);
    for (const ax of ch.axes) {
      const a = `${c}.ax${ax.index}`;
      cells(rowFor(axes, a), [
        `${c} ${ax.name}`, mm(v(`${a}.command_position_acs`)), mm(v(`${a}.command_position_pcs`)),
        mm(v(`${a}.position_offset`)), named(LINK_STATES, v(`${a}.link_state`)), ax.drive || "-",
        referenced(v(`${a}.homing_referenced_r`)),
      ]);
    }
  }
  const c = `ch${state.channel}`;
  const override = v(`${c}.mc_active_feed_override_r`);
  const slider = $("#override");
  if (override !== undefined && document.activeElement !== slider) {
    slider.value = String(Math.round(override / 10));
    $("#override-value").textContent = slider.value;
  }
  const spindle = v(`${c}.mc_spindle_override_w`);
  const spindleSlider = $("#spindle-override");
  if (spindle !== undefined && document.activeElement !== spindleSlider) {
    spindleSlider.value = String(Math.round(spindle / 10));
    $("#spindle-override-value").textContent = spindleSlider.value;
  }
}

// ------------------------------------------------------------------ machine page controls

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
    try {
      await api("POST", "/api/write", { name: `ch${state.channel}.${object}`, value: Number(input.value) * 10 });
      say(`ch${state.channel}.${object} := ${Number(input.value) * 10}`);
    } catch (_) { /* shown */ }
    input.blur();
  });
}
overrideSlider($("#override"), $("#override-value"), "mc_command_feed_override_w");
overrideSlider($("#spindle-override"), $("#spindle-override-value"), "mc_spindle_override_w");

// ------------------------------------------------------------------ program page

async function loadPrograms() {
  const data = await api("GET", "/api/programs");
  const list = $("#program-list");
  list.replaceChildren(...data.programs.map((p) => {
    const item = el("li", { textContent: `${p.name}  (${p.size_bytes} B)` });
    item.dataset.name = p.name;
    item.classList.toggle("selected", p.name === state.program);
    item.addEventListener("click", () => showProgram(p.name));
    return item;
  }));
}

async function showProgram(name) {
  const data = await api("GET", `/api/programs/${encodeURIComponent(name)}`);
  state.program = name;
  state.planned = null;
  state.extent = null;
  if (!working()) state.live = [];
  $("#program-name").textContent = name;
  for (const item of $("#program-list").children) item.classList.toggle("selected", item.dataset.name === name);
  state.programLines = data.text.split("\n");
  if (state.programLines.length && state.programLines[state.programLines.length - 1] === "") state.programLines.pop();
  $("#program-text").replaceChildren(...state.programLines.map((text) => el("li", { textContent: text })));
  state.shownLine = null;
  drawPath();
  await planShown(name);
}

// One dry run at a time in the channel: a plan waits for the one before it, and a
// program no longer shown is not planned at all.
function planShown(name) {
  const mine = (state.planning || Promise.resolve()).then(() => (state.program === name ? loadPlanned(name) : undefined));
  state.planning = mine;
  mine.finally(() => { if (state.planning === mine) state.planning = null; });
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

function setPlanned(trace) {
  const [xName, yName] = Object.keys(trace.positions_mm);
  state.planned = { x: trace.positions_mm[xName] || [], y: trace.positions_mm[yName] || [] };
  state.extent = null;
  drawPath();
}

async function upload(files) {
  for (const file of files) {
    const form = new FormData();
    form.append("file", file, file.name);
    try {
      const done = await api("POST", "/api/programs", form);
      say(`uploaded ${done.name} (${done.size_bytes} bytes)`);
    } catch (_) { return; }
  }
  await loadPrograms();
  if (files.length) await showProgram(files[files.length - 1].name);
}

$("#upload-input").addEventListener("change", (event) => upload([...event.target.files]));
const drop = $("#drop");
drop.addEventListener("dragover", (event) => { event.preventDefault(); drop.classList.add("over"); });
drop.addEventListener("dragleave", () => drop.classList.remove("over"));
drop.addEventListener("drop", (event) => {
  event.preventDefault();
  drop.classList.remove("over");
  if (state.session.may_upload) upload([...event.dataTransfer.files]);
  else say(`role ${state.session.role} may not upload programs; admin may`, true);
});

async function needProgram() {
  if (!state.program) say("choose a program in the list first", true);
  if (state.planning) await state.planning;  // the channel is busy with the dry run until then
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
    state.live = [];
    await api("POST", `/api/channel/${state.channel}/start`, {});
    say(`channel ${state.channel}: ${state.program} started`);
  } catch (_) { /* shown */ }
});

$("#check-program").addEventListener("click", async () => {
  if (!await needProgram()) return;
  try {
    say(`checking ${state.program}…`);
    const result = await api("POST", `/api/channel/${state.channel}/check`, { program: state.program });
    const items = $("#program-text").children;
    for (const item of items) { item.classList.remove("error"); item.querySelector(".err")?.remove(); }
    const found = result.errors.concat(result.aborted ? [result.aborted] : []);
    for (const e of found) {
      const item = e.file === state.program ? items[e.line - 1] : undefined;
      if (!item) continue;
      item.classList.add("error");
      item.append(el("span", { className: "err", textContent: `← error ${e.id} (${e.category}) col ${e.column}: ${e.message}` }));
    }
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

function currentChannel() {
  return state.machine.channels.find((c) => c.id === state.channel);
}

function working() {
  return WORKING_STATES.includes(named(state.machine.states, v(`ch${state.channel}.mc_active_state_r`)));
}

function currentXY(cs = "acs") {
  const ch = currentChannel();
  if (!ch || ch.axes.length < 2) return null;
  const x = v(`ch${ch.id}.ax${ch.axes[0].index}.command_position_${cs}`);
  const y = v(`ch${ch.id}.ax${ch.axes[1].index}.command_position_${cs}`);
  return x === undefined || y === undefined ? null : [x / UM01_PER_MM, y / UM01_PER_MM];
}

// What lies between machine and workpiece coordinates now (zero offset and tool
// length: machine - workpiece), and the name of the coordinates the path is drawn in.
function pathFrame() {
  const acs = currentXY("acs");
  const pcs = currentXY("pcs");
  const shift = acs && pcs ? [acs[0] - pcs[0], acs[1] - pcs[1]] : [0, 0];
  const group = v(`ch${state.channel}.mc_active_zero_offset_r`) || 0;
  const workpiece = group !== 0 || shift[0] !== 0 || shift[1] !== 0;
  return { shift, name: workpiece ? `workpiece coordinates (G${53 + group})` : "machine coordinates (G53)" };
}

function recordLivePath() {
  const here = currentXY();
  if (!here || !working()) return;
  const last = state.live[state.live.length - 1];
  if (!last || last[0] !== here[0] || last[1] !== here[1]) {
    state.live.push(here);
    if (state.live.length > 5000) state.live.splice(0, state.live.length - 5000);
  }
}

function niceStep(span) {
  const raw = span / 5;
  const power = 10 ** Math.floor(Math.log10(raw));
  return [1, 2, 5, 10].map((f) => f * power).find((step) => step >= raw);
}

const PLOT = { left: 46, top: 10, width: 344, height: 262 }; // inside the 400 x 300 view box

function drawPath() {
  const frame = pathFrame();
  const [dx, dy] = frame.shift;
  const toView = ([x, y]) => [x - dx, y - dy];
  const planned = state.planned ? state.planned.x.map((x, k) => toView([x, state.planned.y[k]])) : [];
  const live = state.live.map(toView);
  const acs = currentXY();
  const here = acs ? toView(acs) : null;
  // The view holds the planned path from the start and grows when the tool leaves it:
  // it never shrinks to the path so far. A new offset (G53 -> G54) starts it anew.
  const key = `${dx},${dy}`;
  let e = state.extentKey === key ? state.extent : null;
  for (const [x, y] of planned.concat(live, here ? [here] : [])) {
    e = e ? [Math.min(e[0], x), Math.min(e[1], y), Math.max(e[2], x), Math.max(e[3], y)] : [x, y, x, y];
  }
  if (!e) return;
  state.extent = e;
  state.extentKey = key;
  const span = Math.max((e[2] - e[0]) * PLOT.height / PLOT.width, e[3] - e[1], 1) * 1.1;
  const scale = PLOT.height / span; // px per mm, the same on both axes
  const [cx, cy] = [(e[0] + e[2]) / 2, (e[1] + e[3]) / 2];
  const sx = (x) => PLOT.left + PLOT.width / 2 + (x - cx) * scale;
  const sy = (y) => PLOT.top + PLOT.height / 2 - (y - cy) * scale;
  drawGrid(frame.name, scale, cx, cy, sx, sy);
  const line = (pts) => pts.map(([x, y]) => `${sx(x).toFixed(2)},${sy(y).toFixed(2)}`).join(" ");
  $("#path-planned").setAttribute("points", line(planned));
  $("#path-live").setAttribute("points", line(live));
  if (here) {
    $("#path-tool").setAttribute("cx", sx(here[0]).toFixed(2));
    $("#path-tool").setAttribute("cy", sy(here[1]).toFixed(2));
  }
}

// The axes, the grid and its labels in mm: drawn again only when the view changes.
function drawGrid(frameName, scale, cx, cy, sx, sy) {
  const key = `${frameName} ${scale} ${cx} ${cy}`;
  if (state.gridKey === key) return;
  state.gridKey = key;
  const step = niceStep(PLOT.width / scale);
  const [x0, x1] = [cx - PLOT.width / 2 / scale, cx + PLOT.width / 2 / scale];
  const [y0, y1] = [cy - PLOT.height / 2 / scale, cy + PLOT.height / 2 / scale];
  const digits = step < 1 ? Math.ceil(-Math.log10(step)) : 0;
  const parts = [];
  const bottom = PLOT.top + PLOT.height;
  for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
    const px = sx(x).toFixed(1);
    parts.push(`<line class="${Math.abs(x) < step / 1e6 ? "axis" : "tick"}" x1="${px}" y1="${PLOT.top}" x2="${px}" y2="${bottom}"/>`,
      `<text x="${px}" y="${bottom + 12}" text-anchor="middle">${x.toFixed(digits)}</text>`);
  }
  for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
    const py = sy(y).toFixed(1);
    parts.push(`<line class="${Math.abs(y) < step / 1e6 ? "axis" : "tick"}" x1="${PLOT.left}" y1="${py}" x2="${PLOT.left + PLOT.width}" y2="${py}"/>`,
      `<text x="${PLOT.left - 4}" y="${py}" text-anchor="end" dominant-baseline="middle">${y.toFixed(digits)}</text>`);
  }
  parts.push(`<rect class="frame" x="${PLOT.left}" y="${PLOT.top}" width="${PLOT.width}" height="${PLOT.height}"/>`,
    `<text class="axis-name" x="${PLOT.left + PLOT.width - 2}" y="${bottom - 4}" text-anchor="end">X mm</text>`,
    `<text class="axis-name" x="${PLOT.left + 4}" y="${PLOT.top + 12}">Y mm</text>`);
  $("#path-grid").innerHTML = parts.join("");
  $("#path-frame").textContent = `· ${frameName}`;
  $("#path-scale").textContent = `grid ${step.toFixed(digits)} mm`;
}

function renderProgramPage() {
  const c = `ch${state.channel}`;
  // in step with the channel: its running program is shown, opened while it runs too
  // (once per run: another program may be looked at meanwhile)
  const active = v(`${c}.mc_active_program_name_r`);
  if (!working()) state.followed = null;
  const newRun = working() && active && active !== state.followed;
  if (active && !state.following && (!state.program || newRun)) {
    state.following = true;
    if (working()) state.followed = active;
    if (active === state.program) state.following = false;
    else showProgram(active).catch(() => {}).finally(() => { state.following = false; });
  }
  const here = currentXY(pathFrame().name.startsWith("workpiece") ? "pcs" : "acs");
  if (here) $("#position-line").textContent = `X ${here[0].toFixed(4)}  Y ${here[1].toFixed(4)} mm`;
  $("#program-state").textContent = named(state.machine.states, v(`${c}.mc_active_state_r`));
  const block = v(`${c}.actual_block_number`);
  $("#program-block").textContent = block === undefined || block < 0 ? "-" : `N${block} line ${v(`${c}.mc_active_line_r`)}`;
  const items = $("#program-text").children;
  const line = v(`${c}.mc_active_file_name_r`) === state.program ? v(`${c}.mc_active_line_r`) : null;
  if (line !== state.shownLine) {
    items[state.shownLine - 1]?.classList.remove("current");
    const item = items[line - 1];
    if (item) {
      item.classList.add("current");
      item.scrollIntoView({ block: "nearest" });
    }
    state.shownLine = line;
  }
  drawPath();
}

// ------------------------------------------------------------------ MDI and jog

function mdiHistory() {
  try { return JSON.parse(localStorage.getItem(MDI_HISTORY_KEY) || "[]"); } catch (_) { return []; }
}

function showMdiHistory() {
  $("#mdi-history").replaceChildren(...mdiHistory().map((blocks) => {
    const item = el("li", { textContent: blocks });
    item.addEventListener("click", () => { $("#mdi-input").value = blocks; $("#mdi-input").focus(); });
    return item;
  }));
}

$("#mdi-form").addEventListener("submit", async (event) => {
  event.preventDefault();
  const blocks = $("#mdi-input").value.trim();
  if (!blocks) return;
  try {
    await api("POST", `/api/channel/${state.channel}/mdi`, { blocks });
    const history = [blocks].concat(mdiHistory().filter((b) => b !== blocks)).slice(0, MDI_HISTORY_MAX);
    localStorage.setItem(MDI_HISTORY_KEY, JSON.stringify(history));
    showMdiHistory();
    $("#mdi-input").value = "";
    say(`channel ${state.channel}: manual block ${blocks}`);
  } catch (_) { /* shown */ }
});

const jogMode = () => $("#jog-mode").value;

$("#jog-mode").addEventListener("change", () => {
  const mode = jogMode();
  $("#jog-increment-label").hidden = mode !== "increment";
  $("#jog-rapid-label").hidden = mode !== "continuous";
  $("#jog-handwheel-label").hidden = mode !== "handwheel";
});

function jogButton(ch, ax, direction) {
  const side = direction > 0 ? "plus" : "minus";
  const button = el("button", { type: "button", className: "write jog", textContent: `${ax.name} ${direction > 0 ? "+" : "−"}` });
  button.dataset.key = `ch${ch.id}.ax${ax.index}.manual_jog_${side}_w`;
  button.disabled = !state.session.may_write;
  button.addEventListener("click", () => {
    if (jogMode() === "increment") stepJog(ax, direction);
    else if (jogMode() === "handwheel") turnHandwheel(ax, direction);
  });
  // continuous jog: held while the pointer or the key is down
  button.addEventListener("pointerdown", (event) => {
    if (jogMode() !== "continuous") return;
    button.setPointerCapture(event.pointerId);
    holdJog(ax, direction);
  });
  for (const name of ["pointerup", "pointercancel", "lostpointercapture"]) button.addEventListener(name, releaseJog);
  button.addEventListener("keydown", (event) => {
    if (jogMode() !== "continuous" || (event.key !== " " && event.key !== "Enter")) return;
    event.preventDefault();
    if (!event.repeat) holdJog(ax, direction);
  });
  button.addEventListener("keyup", (event) => {
    if (event.key === " " || event.key === "Enter") releaseJog();
  });
  return button;
}

function renderJog() {
  const ch = currentChannel();
  const tbody = $("#jog tbody");
  if (!ch) return;
  if (tbody.dataset.channel !== String(ch.id)) {
    tbody.dataset.channel = String(ch.id);
    tbody.replaceChildren(...ch.axes.map((ax) => {
      const a = `ch${ch.id}.ax${ax.index}`;
      const home = el("button", { type: "button", className: "write", textContent: `Home ${ax.name}` });
      home.disabled = !state.session.may_write;
      home.addEventListener("click", () => homeAxes([ax]));
      const cell = (name, format) => {
        const td = el("td", { className: "num" });
        td.dataset.value = name;
        td.dataset.format = format;
        return td;
      };
      return el("tr", {}, el("td", {}, jogButton(ch, ax, -1)), cell(`${a}.command_position_acs`, "mm"),
        cell(`${a}.command_position_pcs`, "mm"), el("td", {}, jogButton(ch, ax, 1)),
        cell(`${a}.homing_referenced_r`, "referenced"), el("td", {}, home));
    }));
  }
  for (const cell of tbody.querySelectorAll("td[data-value]")) {
    const value = v(cell.dataset.value);
    const text = cell.dataset.format === "mm" ? mm(value) : referenced(value);
    if (cell.textContent !== text) cell.textContent = text;
  }
  for (const button of tbody.querySelectorAll("button[data-key]")) button.classList.toggle("held", v(button.dataset.key) === true);
  $("#mdi-state").textContent = `channel ${ch.id}: ${named(state.machine.states, v(`ch${ch.id}.mc_active_state_r`))}`;
}

async function stepJog(axis, direction) {
  try {
    await api("POST", `/api/channel/${state.channel}/jog`, { axis: axis.index, direction, increment_mm: Number($("#jog-increment").value) });
    say(`channel ${state.channel}: jog ${axis.name} ${direction > 0 ? "+" : "−"}${$("#jog-increment").value} mm`);
  } catch (_) { /* shown */ }
}

async function turnHandwheel(axis, direction) {
  const pulses = direction * Number($("#jog-pulses").value);
  try {
    await api("POST", `/api/channel/${state.channel}/handwheel`, { axis: axis.index, pulses, resolution_mm: Number($("#jog-resolution").value) });
    say(`channel ${state.channel}: handwheel ${axis.name} ${pulses > 0 ? "+" : ""}${pulses} pulses × ${$("#jog-resolution").value} mm`);
  } catch (_) { /* shown */ }
}

async function homeAxes(axes) {
  try {
    await api("POST", `/api/channel/${state.channel}/home`, { axes: axes.map((a) => a.index) });
    say(`channel ${state.channel}: homing ${axes.map((a) => a.name).join(" ")}`);
  } catch (_) { /* shown */ }
}
$("#home-all").addEventListener("click", () => { const ch = currentChannel(); if (ch) homeAxes(ch.axes); });

// The dead-man: a continuous jog lives on its own WebSocket (/ws/jog). cnc-web releases
// the key when told (key-up, pointer-up, blur, page hidden), when the socket closes, and
// when the page stops renewing it (a hung page): the machine never jogs on unwatched.
const jogLink = { socket: null, opening: null, held: false, timer: null, renewS: 0.25 };

function jogSocket() {
  if (jogLink.socket && jogLink.socket.readyState <= WebSocket.OPEN) return jogLink.opening;
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  const socket = new WebSocket(`${scheme}://${location.host}/ws/jog?csrf=${encodeURIComponent(state.session.csrf || "")}`);
  jogLink.socket = socket;
  jogLink.opening = new Promise((resolve, reject) => {
    socket.addEventListener("open", () => resolve(socket));
    socket.addEventListener("error", () => reject(new Error("the jog connection was refused")));
  });
  socket.addEventListener("message", (event) => {
    const message = JSON.parse(event.data);
    if (message.renew_s) jogLink.renewS = message.renew_s;
    if (message.error) {
      stopRenewing();
      say(message.error, true);
    }
  });
  socket.addEventListener("close", () => {
    stopRenewing();
    if (jogLink.socket === socket) jogLink.socket = null;
  });
  return jogLink.opening;
}

function stopRenewing() {
  clearInterval(jogLink.timer);
  jogLink.timer = null;
}

async function holdJog(axis, direction) {
  jogLink.held = true;
  let socket;
  try { socket = await jogSocket(); } catch (error) { say(error.message, true); return; }
  if (!jogLink.held) return;  // released before the socket was open
  socket.send(JSON.stringify({ press: { channel: state.channel, axis: axis.index, direction, rapid: $("#jog-rapid").checked } }));
  say(`channel ${state.channel}: jog ${axis.name} ${direction > 0 ? "+" : "−"} held`);
  stopRenewing();
  jogLink.timer = setInterval(() => {
    if (socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify({ renew: true }));
  }, jogLink.renewS * 1000);
}

function releaseJog() {
  if (!jogLink.held) return;
  jogLink.held = false;
  stopRenewing();
  if (jogLink.socket && jogLink.socket.readyState === WebSocket.OPEN) jogLink.socket.send(JSON.stringify({ release: true }));
}
window.addEventListener("blur", releaseJog);
window.addEventListener("pagehide", releaseJog);
document.addEventListener("visibilitychange", () => { if (document.hidden) releaseJog(); });

// ------------------------------------------------------------------ tools and offsets

function numberInput(value) {
  const input = el("input", { type: "number", step: "any", className: "write", value: String(value) });
  input.disabled = !state.session.may_write;
  return input;
}

function finite(inputs) {
  const values = inputs.map((input) => Number(input.value));
  if (inputs.some((input) => input.value.trim() === "") || !values.every(Number.isFinite)) {
    say("give a number of mm in every field", true);
    return null;
  }
  return values;
}

async function loadTools() {
  const c = state.channel;
  const [tools, offsets] = await Promise.all([api("GET", `/api/channel/${c}/tools`), api("GET", `/api/channel/${c}/offsets`)]);
  $("#tool-active").textContent = `· channel ${c}: T${tools.active_tool} in the spindle (T${tools.selected_tool} selected), D${tools.d}`;
  $("#tool-table tbody").replaceChildren(...tools.rows.map((row) => {
    const valid = el("input", { type: "checkbox", className: "write", checked: row.valid });
    valid.disabled = !state.session.may_write;
    const radius = numberInput(row.radius_mm);
    const length = numberInput(row.length_mm);
    const save = el("button", { type: "button", className: "write", textContent: "Save" });
    save.disabled = !state.session.may_write;
    save.addEventListener("click", async () => {
      const values = finite([radius, length]);
      if (!values) return;
      try {
        await api("POST", `/api/channel/${c}/tools/${row.d}`, { radius_mm: values[0], length_mm: values[1], valid: valid.checked });
        say(`channel ${c}: wz[${row.d}] written`);
        await loadTools();
      } catch (_) { /* shown */ }
    });
    const tr = el("tr", {}, el("td", { textContent: `D${row.d}` }), el("td", {}, valid), el("td", {}, radius), el("td", {}, length), el("td", {}, save));
    tr.dataset.d = String(row.d);
    tr.classList.toggle("active-row", row.d === tools.d);
    return tr;
  }));
  $("#offset-active").textContent = `· channel ${c}: G${53 + offsets.active} in effect`;
  $("#offset-table thead tr").replaceChildren(el("th", { textContent: "group" }),
    ...offsets.axes.map((name) => el("th", { textContent: `${name} mm` })), el("th"));
  $("#offset-table tbody").replaceChildren(...offsets.rows.map((row) => {
    const inputs = row.offsets_mm.map(numberInput);
    const save = el("button", { type: "button", className: "write", textContent: "Save" });
    save.disabled = !state.session.may_write;
    save.addEventListener("click", async () => {
      const values = finite(inputs);
      if (!values) return;
      const offsetsMm = Object.fromEntries(values.map((value, k) => [String(k + 1), value]));
      try {
        await api("POST", `/api/channel/${c}/offsets/${row.group}`, { offsets_mm: offsetsMm });
        say(`channel ${c}: zero offset ${row.name} written`);
        await loadTools();
      } catch (_) { /* shown */ }
    });
    const tr = el("tr", {}, el("td", { textContent: row.name }), ...inputs.map((input) => el("td", {}, input)), el("td", {}, save));
    tr.dataset.group = String(row.group);
    tr.classList.toggle("active-row", row.group === offsets.active);
    return tr;
  }));
}

// ------------------------------------------------------------------ look-ahead

async function lookahead(mode) {
  try {
    const data = await api("GET", `/api/channel/${state.channel}/lookahead?mode=${mode}`);
    $("#lookahead-state").textContent = `${data.count_logged_blocks} logged, log ${data.log_active ? "active" : "off"}, max_dist_prog_start ${mm(data.max_dist_prog_start)} mm`;
    const deg = (rad) => (rad * 180 / Math.PI).toFixed(3);
    $("#lookahead-table tbody").replaceChildren(...data.blocks.map((b, k) => {
      const row = el("tr");
      cells(row, [k, named(CONTOUR_TYPES, b.block_type), b.block_number, mm(b.start_position), mm(b.length),
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

// ------------------------------------------------------------------ alarms

const alarmTime = (iso) => (iso ? new Date(iso).toLocaleString() : "-");
const alarmCells = (a) => [a.sequence, alarmTime(a.time), a.channel || "-", a.id, a.severity, a.state,
  a.file ? `${a.file}:${a.line}:${a.column}` : "-", a.text];

async function loadAlarms() {
  const data = await api("GET", "/api/alarms");
  $("#alarm-none").hidden = data.alarms.length > 0;
  $("#alarm-ack-all").disabled = !state.session.may_write || !data.alarms.some((a) => a.state === "active");
  $("#alarm-table tbody").replaceChildren(...data.alarms.map((a) => {
    const ack = el("button", { type: "button", className: "write", textContent: "Acknowledge" });
    ack.disabled = !state.session.may_write || a.state !== "active";
    ack.addEventListener("click", async () => {
      try {
        await api("POST", `/api/alarms/${a.sequence}/acknowledge`, {});
        say(`alarm #${a.sequence} (${a.id}) acknowledged`);
        await loadAlarms();
      } catch (_) { /* shown */ }
    });
    const row = el("tr");
    cells(row, alarmCells(a));
    row.append(el("td", {}, ack));
    return row;
  }));
  if (state.page === "alarms") loadAlarmHistory().catch(() => {});
  return data.alarms;
}

async function loadAlarmHistory() {
  const data = await api("GET", "/api/alarms/history");
  $("#alarm-history tbody").replaceChildren(...data.alarms.map((a) => {
    const row = el("tr");
    cells(row, alarmCells(a));
    return row;
  }));
}

$("#alarm-ack-all").addEventListener("click", async () => {
  try {
    await api("POST", "/api/alarms/acknowledge-all", {});
    say("all alarms acknowledged (an error stays until RESET)");
    await loadAlarms();
  } catch (_) { /* shown */ }
});

async function showNewestAlarm() {
  try {
    const alarms = await loadAlarms();
    const newest = alarms.filter((a) => a.channel === state.channel || a.channel === 0).pop();
    if (newest) say(`channel ${newest.channel}: ${newest.severity} ${newest.id}: ${newest.file ? `${newest.file}:${newest.line}:${newest.column}: ` : ""}${newest.text}`, newest.severity === "error");
  } catch (_) { /* shown */ }
}

// ------------------------------------------------------------------ objects (ADS monitor)

$("#object-search").addEventListener("submit", async (event) => {
  event.preventDefault();
  try {
    const pattern = $("#object-pattern").value.trim() || "*";
    const data = await api("GET", `/api/objects?pattern=${encodeURIComponent(pattern)}&limit=300`);
    $("#object-total").textContent = `${data.objects.length} of ${data.total}`;
    $("#object-table tbody").replaceChildren(...data.objects.map((o) => {
      const row = el("tr");
      row.title = o.description;
      cells(row, [o.name, `${o.port}:0x${o.group.toString(16)}:0x${o.offset.toString(16)}`, o.type, o.access, o.unit]);
      const watchButton = el("button", { type: "button", textContent: "Watch" });
      watchButton.addEventListener("click", () => addWatch(o));
      row.append(el("td", {}, watchButton));
      return row;
    }));
  } catch (_) { /* shown */ }
});

const objectAccess = {};

function addWatch(info) {
  if (state.objectWatch.includes(info.name)) return;
  objectAccess[info.name] = info.access;
  state.objectWatch.push(info.name);
  watch([info.name]);
  const input = el("input", { type: "text", className: "write", placeholder: "value" });
  const set = el("button", { type: "button", className: "write", textContent: "Write" });
  input.disabled = set.disabled = !state.session.may_write || !info.access.includes("w");
  set.addEventListener("click", async () => {
    let value = input.value;
    try { value = JSON.parse(value); } catch (_) { /* a bare string */ }
    try {
      await api("POST", "/api/write", { name: info.name, value });
      say(`${info.name} := ${input.value}`);
    } catch (_) { /* shown */ }
  });
  const remove = el("button", { type: "button", textContent: "×", title: "stop watching" });
  const valueCell = el("td", { className: "num" });
  valueCell.dataset.watch = info.name;
  const row = el("tr", {}, el("td", { textContent: info.name }), valueCell, el("td", {}, input, set), el("td", {}, remove));
  remove.addEventListener("click", () => {
    state.objectWatch = state.objectWatch.filter((n) => n !== info.name);
    unwatch([info.name]);
    row.remove();
  });
  $("#watch-table tbody").append(row);
  renderWatch();
}

function renderWatch() {
  for (const cell of document.querySelectorAll("td[data-watch]")) {
    const name = cell.dataset.watch;
    const text = name in state.watchErrors ? state.watchErrors[name] : JSON.stringify(v(name) ?? "…");
    if (cell.textContent !== text) cell.textContent = text;
  }
}

// ------------------------------------------------------------------ pages and start

function showPage() {
  const name = PAGES.includes(location.hash.slice(1)) ? location.hash.slice(1) : "machine";
  for (const page of PAGES) $(`#page-${page}`).hidden = page !== name;
  for (const link of document.querySelectorAll("#nav a")) link.classList.toggle("active", link.getAttribute("href") === `#${name}`);
  document.body.dataset.page = name;
  state.page = name;
  const loaders = { program: loadPrograms, alarms: loadAlarms, mdi: showMdiHistory, tools: loadTools };
  if (loaders[name]) Promise.resolve(loaders[name]()).catch(() => {});
  queueRender();
}

$("#channel-select").addEventListener("change", (event) => {
  state.channel = Number(event.target.value);
  state.live = [];
  state.extent = null;
  if (state.page === "tools") loadTools().catch(() => {});
  queueRender();
});

async function start() {
  const session = await loadSession();
  if (!session.role) { showLogin(); return; }
  state.machine = await api("GET", "/api/machine");
  $("#channel-select").replaceChildren(...state.machine.channels.map((c) => el("option", { value: c.id, textContent: `channel ${c.id}` })));
  state.channel = state.machine.channels.length ? state.machine.channels[0].id : 1;
  window.addEventListener("hashchange", showPage);
  showPage();
  connectLive();
  document.body.dataset.ready = "1"; // the tests wait for it
}

start().catch((error) => say(`cnc-web: ${error.message}`, true));
