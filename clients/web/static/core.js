// cnc-web's core: the state shared by the pages, the facts of the service, the JSON API
// and the message line, and the helpers every page draws with.
//
// Module layout (ES modules, no build step, no library, no CDN): main.js starts the page
// and imports every page module; core.js (this), live.js (the WebSocket of live values)
// and router.js (pages and the render queue) are the core; one module per page renders
// that page only: machine.js, program.js (with program_lines.js, upload.js, toolpath.js),
// mdi.js (with jog.js), tools.js, lookahead.js, alarms.js, objects.js.
//
// Facts are not typed here: the scale of lengths, the value names (states, spindle modes,
// link states, look-ahead block types) and the engineering unit of each object come from
// the service's Python constants through GET /api/facts, loaded once at start.

export const state = {
  session: null,
  machine: null,
  channel: 1,
  values: {},          // object name -> newest value
  watchErrors: {},     // object name -> why it cannot be watched
  socket: null,
  program: null,       // the program shown on the program page
  page: "machine",
  objectWatch: [],     // names on the objects page's watch list
  // rendered: page -> frames drawn (only the visible page is drawn)
  stats: { messages: 0, positionUpdates: 0, rendered: {}, since: performance.now() },
};
window.cncStats = state.stats; // read by the tests and the benchmark

// GET /api/facts: {um01_per_mm, modes, states, working_states, spindle_modes,
// link_states, contour_types, scales: {leaf: {unit, factor, decimals}}}
export const facts = {};

export const $ = (sel) => document.querySelector(sel);
export const el = (tag, props = {}, ...children) => {
  const node = Object.assign(document.createElement(tag), props);
  for (const child of children) node.append(child);
  return node;
};

// ------------------------------------------------------------------ message line

export function say(text, isError = false) {
  const line = $("#message");
  line.textContent = text;
  line.classList.toggle("error", isError);
}

// ------------------------------------------------------------------ API
// Every write goes through the JSON API with the session's CSRF token; a refusal is shown
// on the message line in the service's words.

export async function api(method, path, body, quiet = false) {
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

export function showLogin() {
  for (const page of document.querySelectorAll(".page")) page.hidden = true;
  const roles = $("#login-role");
  roles.replaceChildren(...(state.session ? state.session.roles : []).map((r) => el("option", { value: r, textContent: r })));
  $("#login").hidden = false;
  say("sign in with a role's password");
}

export async function loadFacts() {
  Object.assign(facts, await api("GET", "/api/facts"));
}

// ------------------------------------------------------------------ values as people read them

export const v = (name) => state.values[name];
export const named = (table, value) => (value === undefined ? "-" : (table[value] || String(value)));
export const referenced = (value) => (value === undefined ? "-" : (value ? "yes" : "no"));
// digits of a mm that the 0.1 um steps resolve
const mmDecimals = () => Math.round(Math.log10(facts.um01_per_mm));
// a length in 0.1 um as mm
export const mm = (value) => (value === undefined ? "-" : (value / facts.um01_per_mm).toFixed(mmDecimals()));
export const toMm = (value) => value / facts.um01_per_mm;
// ``ch1.mc_active_feedrate_r`` -> its scale ({unit, factor, decimals}) of the catalog
export const scaleOf = (name) => facts.scales[name.slice(name.lastIndexOf(".") + 1)];
// an object's value in its engineering unit (mm/min, %, rpm), undefined when unknown
export const scaled = (name, value = v(name)) => (value === undefined ? undefined : value * scaleOf(name).factor);
// an engineering value (a slider's %) as the object's raw value
export const raw = (name, value) => Math.round(value / scaleOf(name).factor);

export function currentChannel() {
  return state.machine.channels.find((c) => c.id === state.channel);
}

export function working() {
  return facts.working_states.includes(named(facts.states, v(`ch${state.channel}.mc_active_state_r`)));
}

// The tool's X and Y in mm (machine "acs" or workpiece "pcs" coordinates), or null.
export function currentXY(cs = "acs") {
  const ch = currentChannel();
  if (!ch || ch.axes.length < 2) return null;
  const x = v(`ch${ch.id}.ax${ch.axes[0].index}.command_position_${cs}`);
  const y = v(`ch${ch.id}.ax${ch.axes[1].index}.command_position_${cs}`);
  return x === undefined || y === undefined ? null : [toMm(x), toMm(y)];
}

// ------------------------------------------------------------------ drawing
// Writing the text or attribute a node already has still costs the browser a style and
// layout pass: a frame writes only what changed.

export function setText(node, text) {
  if (node.textContent !== text) node.textContent = text;
}

export function setAttr(node, name, value) {
  if (node.getAttribute(name) !== value) node.setAttribute(name, value);
}

// ------------------------------------------------------------------ tables

export function cells(row, values) {
  if (row.children.length !== values.length) row.replaceChildren(...values.map(() => el("td")));
  values.forEach((value, k) => {
    const cell = row.children[k];
    setText(cell, String(value));
    if (typeof value === "string" && /^-?\d+\.\d+$/.test(value)) cell.className = "num";
  });
}

const tableRows = new WeakMap(); // tbody -> Map(key -> row): no query per row and frame

export function rowFor(tbody, key) {
  if (!tableRows.has(tbody)) tableRows.set(tbody, new Map());
  const rows = tableRows.get(tbody);
  let row = rows.get(key);
  if (!row || row.parentNode !== tbody) {
    row = el("tr");
    row.dataset.key = key;
    tbody.append(row);
    rows.set(key, row);
  }
  return row;
}

export function sizeText(bytes) {
  return bytes < 1e6 ? `${bytes} B` : `${(bytes / 1e6).toFixed(1)} MB`;
}
