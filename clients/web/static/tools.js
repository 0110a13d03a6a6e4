// cnc-web: the Tools / Offsets page: the tool list and the zero offset table of the channel,
// edited row by row. Loaded when the page is shown and when the channel changes on it;
// nothing live to draw.

import { $, api, el, say, state } from "./core.js";
import { definePage, onChannel } from "./router.js";

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

onChannel(() => { if (state.page === "tools") loadTools().catch(() => {}); });
definePage("tools", { show: loadTools });
