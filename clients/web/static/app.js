// cnc-web: the browser side. Plain JavaScript, no build step, no library, no CDN.
// app.js holds the state, the API, the live values and most pages; toolpath.js, jog.js
// and tools.js (classic scripts loaded after it) the tool path, jog and the tools page.
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
const WINDOW_LINES = 200;           // lines of a program shown at once (fetched by range)
const WINDOW_LEAD = 50;             // lines shown above the current block when following it
const PLAN_AUTO_MAX_BYTES = 2 << 20; // larger programs are planned on "Draw path" only

const state = {
  session: null,
  machine: null,
  channel: 1,
  values: {},          // object name -> newest value
  watchErrors: {},     // object name -> why it cannot be watched
  socket: null,
  program: null,       // the program shown on the program page
  programWindow: null, // {first, lines, total}: the lines shown (a window of the program)
  programSizes: {},    // program name -> size in bytes (the store's list)
  checkErrors: {},     // line -> error text of the last syntax check of the shown program
  upload: null,        // {id, name, controller, cancelled} of the upload under way
  followLines: true,   // the window follows the running program's line (until paged by hand)
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
  state.programSizes = Object.fromEntries(data.programs.map((p) => [p.name, p.size_bytes]));
  list.replaceChildren(...data.programs.map((p) => {
    const item = el("li", { textContent: `${p.name}  (${sizeText(p.size_bytes)})` });
    item.dataset.name = p.name;
    item.classList.toggle("selected", p.name === state.program);
    item.addEventListener("click", () => showProgram(p.name));
    return item;
  }));
}

function sizeText(bytes) {
  return bytes < 1e6 ? `${bytes} B` : `${(bytes / 1e6).toFixed(1)} MB`;
}

async function showProgram(name) {
  const part = await fetchLines(name, 1);
  state.program = name;
  state.planned = null;
  state.extent = null;
  state.checkErrors = {};
  state.followLines = true;
  if (!working()) state.live = [];
  $("#program-name").textContent = name;
  for (const item of $("#program-list").children) item.classList.toggle("selected", item.dataset.name === name);
  showWindow(part);
  drawPath();
  if ((state.programSizes[name] ?? 0) > PLAN_AUTO_MAX_BYTES) {
    $("#path-note").textContent = "a large program: Draw path plans it (a dry run)";
    return;
  }
  await planShown(name);
}

// ------------------------------------------------------------------ the program's lines, a window at a time
// A program of hundreds of MB is never loaded whole: cnc-web reads the lines shown from
// the service (GET /api/programs/NAME/lines), WINDOW_LINES at a time.

async function fetchLines(name, first) {
  const data = await api("GET", `/api/programs/${encodeURIComponent(name)}/lines?first=${Math.max(1, first)}&count=${WINDOW_LINES}`);
  return { first: data.first_line, lines: data.lines, total: data.total_lines };
}

function showWindow(part) {
  state.programWindow = part;
  const list = $("#program-text");
  list.start = part.first;
  list.replaceChildren(...part.lines.map((text, k) => {
    const item = el("li", { textContent: text });
    const error = state.checkErrors[part.first + k];
    if (error) {
      item.classList.add("error");
      item.append(el("span", { className: "err", textContent: error }));
    }
    return item;
  }));
  const last = part.first + part.lines.length - 1;
  $("#lines-shown").textContent = part.lines.length
    ? `lines ${part.first}–${last} of ${part.total}` : `${part.total} lines`;
  $("#lines-previous").disabled = $("#lines-first").disabled = part.first <= 1;
  $("#lines-next").disabled = $("#lines-last").disabled = last >= part.total;
  state.shownLine = null;
}

// Show the window that starts at line ``first`` (one request at a time: a newer wish
// replaces one not yet sent).
async function goToLine(first, scrollTo = null) {
  const name = state.program;
  if (!name || !state.programWindow) return;
  first = Math.max(1, Math.min(first, state.programWindow.total - WINDOW_LINES + 1));
  state.wantedFirst = first;
  if (state.windowLoading) return;
  state.windowLoading = true;
  try {
    while (state.wantedFirst !== null && state.program === name) {
      const wanted = state.wantedFirst;
      state.wantedFirst = null;
      if (wanted === state.programWindow.first) continue;
      const part = await fetchLines(name, wanted);
      if (state.program === name) showWindow(part);
    }
  } catch (_) { /* shown on the message line */ } finally {
    state.windowLoading = false;
  }
  if (scrollTo !== null) $("#program-text").children[scrollTo - state.programWindow.first]?.scrollIntoView({ block: "center" });
}

// Paging by hand stops the window from following the running program; "current" (or
// opening a program) makes it follow again.
const windowFirst = () => (state.programWindow ? state.programWindow.first : 1);
const browse = (first, scrollTo = null) => { state.followLines = false; return goToLine(first, scrollTo); };
$("#lines-first").addEventListener("click", () => browse(1));
$("#lines-previous").addEventListener("click", () => browse(windowFirst() - WINDOW_LINES));
$("#lines-next").addEventListener("click", () => browse(windowFirst() + WINDOW_LINES));
$("#lines-last").addEventListener("click", () => browse(state.programWindow ? state.programWindow.total : 1));
$("#lines-current").addEventListener("click", () => {
  state.followLines = true;
  const line = v(`ch${state.channel}.mc_active_line_r`);
  if (line > 0) goToLine(line - WINDOW_LEAD, line);
});
$("#lines-goto").addEventListener("change", (event) => {
  const line = Number(event.target.value);
  if (Number.isInteger(line) && line >= 1) browse(line - WINDOW_LEAD, line);
});
// scrolling past either end of the window brings the lines beyond it (half a window on)
$("#program-text").addEventListener("scroll", (event) => {
  const list = event.target;
  const shown = state.programWindow;
  if (!shown || state.windowLoading) return;
  const half = WINDOW_LINES / 2;
  if (list.scrollTop + list.clientHeight >= list.scrollHeight - 2 && shown.first + shown.lines.length - 1 < shown.total) {
    goToLine(shown.first + half, shown.first + shown.lines.length - 1);
  } else if (list.scrollTop <= 0 && shown.first > 1) {
    goToLine(shown.first - half, shown.first);
  }
});

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

// A program goes in slices of the File (never read whole into the page): each slice is
// one request that cnc-web forwards to the service's chunked upload as it arrives. The
// bar shows what cnc-web received; Cancel (or a closed tab) abandons the upload.
async function upload(files) {
  for (const file of files) {
    try {
      await uploadFile(file);
      say(`uploaded ${file.name} (${sizeText(file.size)})`);
    } catch (error) {
      say(state.upload && state.upload.cancelled ? `upload of ${file.name} cancelled` : error.message, true);
      return;
    } finally {
      state.upload = null;
      $("#upload").hidden = true;
      $("#upload-input").value = "";
    }
  }
  await loadPrograms();
  if (files.length) await showProgram(files[files.length - 1].name);
}

async function uploadFile(file) {
  if (state.upload) throw new Error(`an upload (${state.upload.name}) is under way: wait for it or cancel it`);
  state.upload = { id: null, name: file.name, controller: new AbortController(), cancelled: false };
  const started = performance.now();
  const progress = (received) => {
    const s = (performance.now() - started) / 1000;
    $("#upload-progress").value = file.size ? received / file.size : 1;
    $("#upload-status").textContent = `${file.name}: ${sizeText(received)} of ${sizeText(file.size)} ` +
      `(${file.size ? Math.floor(received / file.size * 100) : 100} %)` + (s > 0.5 ? ` · ${(received / 1e6 / s).toFixed(1)} MB/s` : "");
  };
  progress(0);
  $("#upload").hidden = false;
  const opened = await api("POST", "/api/uploads", { name: file.name, size_bytes: file.size }, true);
  state.upload.id = opened.upload;
  let at = 0;
  while (at < file.size) {
    const response = await fetch(`/api/uploads/${opened.upload}?at=${at}`, {
      method: "PUT", body: file.slice(at, at + opened.slice_bytes), credentials: "same-origin",
      headers: { "X-CSRF-Token": state.session.csrf, "Content-Type": "application/octet-stream" },
      signal: state.upload.controller.signal,
    });
    let data = {};
    try { data = await response.json(); } catch (_) { data = {}; }
    if (!response.ok) throw new Error(data.error || `${response.status} ${response.statusText}`);
    at = data.received_bytes;
    progress(at);
  }
  await api("POST", `/api/uploads/${opened.upload}/commit`, {}, true);
}

$("#upload-cancel").addEventListener("click", async () => {
  const running = state.upload;
  if (!running) return;
  running.cancelled = true;
  running.controller.abort();  // a slice on its way is dropped: cnc-web abandons the upload
  if (running.id) await api("DELETE", `/api/uploads/${running.id}`, undefined, true).catch(() => {});
});

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
    const found = result.errors.concat(result.aborted ? [result.aborted] : []);
    state.checkErrors = {};
    for (const e of found) {
      if (e.file === state.program) state.checkErrors[e.line] = `← error ${e.id} (${e.category}) col ${e.column}: ${e.message}`;
    }
    if (state.programWindow) showWindow(state.programWindow);  // the errors of the lines shown
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
  const first = windowFirst();
  if (line !== state.shownLine) {
    items[state.shownLine - first]?.classList.remove("current");
    const item = items[line - first];
    if (item) {
      item.classList.add("current");
      item.scrollIntoView({ block: "nearest" });
    } else if (line > 0 && working() && state.followLines && !state.windowLoading && !state.planning) {
      // the run left the window: the window follows it (not the page's own dry run that
      // plans the path: that one runs through the program while nobody started it)
      goToLine(line - WINDOW_LEAD);
    }
    state.shownLine = item ? line : null;
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
      cells(row, [o.name, `${o.port}:0x${o.group.toString(16)}:0x${o.offset.toString(16)}`, o.type, o.access,
        o.scale ? `${o.scale.unit} (${o.unit})` : o.unit]);
      const watchButton = el("button", { type: "button", textContent: "Watch" });
      watchButton.addEventListener("click", () => addWatch(o));
      row.append(el("td", {}, watchButton));
      return row;
    }));
  } catch (_) { /* shown */ }
});

const objectAccess = {};
// The engineering scale of each watched object, from browse ([unit, factor, decimals]
// of the catalog): values are shown and written in mm, %, rpm, as the CLI does.
const objectScale = {};
const objectRawUnit = {};

function engineeringText(name, value) {
  const scale = objectScale[name];
  if (!scale || typeof value !== "number") return JSON.stringify(value ?? "…");
  return `${(value * scale.factor).toFixed(scale.decimals)} ${scale.unit}`;
}

function addWatch(info) {
  if (state.objectWatch.includes(info.name)) return;
  objectAccess[info.name] = info.access;
  objectScale[info.name] = info.scale;
  objectRawUnit[info.name] = info.unit;
  state.objectWatch.push(info.name);
  watch([info.name]);
  const input = el("input", { type: "text", className: "write", placeholder: info.scale ? `value in ${info.scale.unit}` : "value" });
  const set = el("button", { type: "button", className: "write", textContent: "Write" });
  input.disabled = set.disabled = !state.session.may_write || !info.access.includes("w");
  set.addEventListener("click", async () => {
    let value = input.value;
    try { value = JSON.parse(value); } catch (_) { /* a bare string */ }
    try {
      await api("POST", "/api/write", { name: info.name, value, units: Boolean(info.scale) });
      say(`${info.name} := ${input.value}${info.scale ? " " + info.scale.unit : ""}`);
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
    const text = name in state.watchErrors ? state.watchErrors[name] : engineeringText(name, v(name));
    if (cell.textContent !== text) {
      cell.textContent = text;
      cell.title = objectScale[name] ? `raw ${JSON.stringify(v(name))} ${objectRawUnit[name]}` : "";
    }
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

// after every deferred script (toolpath.js, jog.js, tools.js) has run
document.addEventListener("DOMContentLoaded", () => start().catch((error) => say(`cnc-web: ${error.message}`, true)));
