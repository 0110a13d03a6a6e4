// cnc-web: the Objects page (an ADS monitor): browse the catalog by glob, watch objects
// live and write them, in the engineering unit of the catalog's scale (mm, %, rpm, as the
// CLI does); the raw value in the cell's title.

import { $, api, cells, el, say, state, v } from "./core.js";
import { unwatch, watch } from "./live.js";
import { definePage } from "./router.js";

const watched = {};  // name -> {scale: {unit, factor, decimals} | null, unit} of browse

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

function engineeringText(name, value) {
  const scale = watched[name].scale;
  if (!scale || typeof value !== "number") return JSON.stringify(value ?? "…");
  return `${(value * scale.factor).toFixed(scale.decimals)} ${scale.unit}`;
}

function addWatch(info) {
  if (state.objectWatch.includes(info.name)) return;
  watched[info.name] = { scale: info.scale, unit: info.unit };
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
      cell.title = watched[name].scale ? `raw ${JSON.stringify(v(name))} ${watched[name].unit}` : "";
    }
  }
}

definePage("objects", { render: renderWatch });
