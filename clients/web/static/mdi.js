// cnc-web: the MDI / Jog page: manual blocks (with a history kept in the browser) and
// the jog table of jog.js, the one thing the page draws each frame.

import { $, api, el, say, state } from "./core.js";
import { renderJog } from "./jog.js";
import { definePage } from "./router.js";

const MDI_HISTORY_KEY = "cnc-web-mdi-history";
const MDI_HISTORY_MAX = 30;

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

definePage("mdi", { render: renderJog, show: showMdiHistory });
