// cnc-web: the start of the page (the one <script type="module"> of index.html): the
// session and sign-in, the facts of the service, the channel chooser, the router and the
// live values. Importing a page module registers the page (router.definePage).

import { $, api, el, loadFacts, say, showLogin, state } from "./core.js";
import { connectLive } from "./live.js";
import { changeChannel, showPage } from "./router.js";
import "./machine.js";
import "./program.js";
import "./mdi.js";
import "./tools.js";
import "./lookahead.js";
import "./alarms.js";
import "./objects.js";

async function loadSession() {
  state.session = await api("GET", "/api/session");
  const s = state.session;
  $("#who").textContent = s.role ? `${s.role} · ${s.endpoint}` : "";
  $("#logout").hidden = !(s.sign_in_required && s.role);
  for (const control of document.querySelectorAll(".write")) control.disabled = !s.may_write;
  $("#upload-input").disabled = !s.may_upload;  // the program store: admin, as on the service
  return s;
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

$("#channel-select").addEventListener("change", (event) => changeChannel(Number(event.target.value)));

async function start() {
  const session = await loadSession();
  if (!session.role) { showLogin(); return; }
  const [machine] = await Promise.all([api("GET", "/api/machine"), loadFacts()]);
  state.machine = machine;
  $("#channel-select").replaceChildren(...state.machine.channels.map((c) => el("option", { value: c.id, textContent: `channel ${c.id}` })));
  state.channel = state.machine.channels.length ? state.machine.channels[0].id : 1;
  window.addEventListener("hashchange", showPage);
  showPage();
  connectLive();
  document.body.dataset.ready = "1"; // the tests wait for it
}

// a module runs after the document is parsed (as a deferred script)
start().catch((error) => say(`cnc-web: ${error.message}`, true));
