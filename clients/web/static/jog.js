// cnc-web: jog on the MDI / Jog page: by increments, continuous (held by the dead-man
// socket /ws/jog), handwheel, homing; the jog table with the axes' positions.

import { $, api, currentChannel, el, facts, mm, named, referenced, say, state, v } from "./core.js";

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

export function renderJog() {
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
  const said = `channel ${ch.id}: ${named(facts.states, v(`ch${ch.id}.mc_active_state_r`))}`;
  if ($("#mdi-state").textContent !== said) $("#mdi-state").textContent = said;
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
