// cnc-web: the Alarms page (the active list with acknowledge, the history) and, on every
// page, the count of active alarms on the navigation bar and the newest alarm of the
// channel on the message line when one is raised.

import { $, api, cells, el, say, state } from "./core.js";
import { onValue } from "./live.js";
import { definePage, onEveryFrame } from "./router.js";

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

onValue("alarm_raised_r", (raised, before) => {
  if (before !== undefined && raised > before) showNewestAlarm();
});

// the service's active alarm list, counted on the navigation bar whatever page is shown
onEveryFrame(() => {
  const active = state.values["alarm_active_count_r"] || 0;
  const text = active ? String(active) : "";
  const badge = $("#alarm-count");
  if (badge.textContent !== text) badge.textContent = text;
});

definePage("alarms", { show: loadAlarms });
