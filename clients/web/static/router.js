// cnc-web: the pages and the render queue. The URL's fragment (#machine, #program, ...)
// names the visible page. Live values queue one frame (requestAnimationFrame); a frame
// draws the visible page only: a hidden page costs nothing, and draws once when shown.

import { $, state } from "./core.js";

export const PAGES = ["machine", "program", "mdi", "tools", "lookahead", "alarms", "objects"];
const pages = {};       // name -> {render(), show()}: draw a frame; load what the page lists
const everyFrame = [];  // small work of every frame whatever page is shown
const channelHooks = []; // called when the channel the commands act on changes

// A page module says how it draws (``render``, each frame while visible) and what it
// loads when it becomes visible (``show``).
export function definePage(name, spec) {
  pages[name] = spec;
}

export function onEveryFrame(work) {
  everyFrame.push(work);
}

export function onChannel(hook) {
  channelHooks.push(hook);
}

let renderQueued = false;

export function queueRender() {
  if (renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    render();
  });
}

function render() {
  for (const work of everyFrame) work();
  const page = pages[state.page];
  if (!page || !page.render) return;
  state.stats.rendered[state.page] = (state.stats.rendered[state.page] || 0) + 1;
  page.render();
}

export function showPage() {
  const name = PAGES.includes(location.hash.slice(1)) ? location.hash.slice(1) : "machine";
  for (const page of PAGES) $(`#page-${page}`).hidden = page !== name;
  for (const link of document.querySelectorAll("#nav a")) link.classList.toggle("active", link.getAttribute("href") === `#${name}`);
  document.body.dataset.page = name;
  state.page = name;
  const shown = pages[name] && pages[name].show;
  if (shown) Promise.resolve(shown()).catch(() => {});
  queueRender();
}

export function changeChannel(id) {
  state.channel = id;
  for (const hook of channelHooks) hook();
  queueRender();
}
