// cnc-web: the program's lines, a window at a time. A program of hundreds of MB is never
// loaded whole: the page reads the lines shown from the service
// (GET /api/programs/NAME/lines), WINDOW_LINES at a time.

import { $, api, el, state, v } from "./core.js";

export const WINDOW_LINES = 200;  // lines of a program shown at once (fetched by range)
export const WINDOW_LEAD = 50;    // lines shown above the current block when following it

export const lines = {
  window: null,       // {first, lines, total}: the lines shown (a window of the program)
  checkErrors: {},    // line -> error text of the last syntax check of the shown program
  follow: true,       // the window follows the running program's line (until paged by hand)
  loading: false,     // a window is being fetched
  wantedFirst: null,  // the first line of the window wished next
  shownLine: null,    // the line marked current
};

export async function fetchLines(name, first) {
  const data = await api("GET", `/api/programs/${encodeURIComponent(name)}/lines?first=${Math.max(1, first)}&count=${WINDOW_LINES}`);
  return { first: data.first_line, lines: data.lines, total: data.total_lines };
}

export function showWindow(part) {
  lines.window = part;
  const list = $("#program-text");
  list.start = part.first;
  list.replaceChildren(...part.lines.map((text, k) => {
    const item = el("li", { textContent: text });
    const error = lines.checkErrors[part.first + k];
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
  lines.shownLine = null;
}

// Show the window that starts at line ``first`` (one request at a time: a newer wish
// replaces one not yet sent).
export async function goToLine(first, scrollTo = null) {
  const name = state.program;
  if (!name || !lines.window) return;
  first = Math.max(1, Math.min(first, lines.window.total - WINDOW_LINES + 1));
  lines.wantedFirst = first;
  if (lines.loading) return;
  lines.loading = true;
  try {
    while (lines.wantedFirst !== null && state.program === name) {
      const wanted = lines.wantedFirst;
      lines.wantedFirst = null;
      if (wanted === lines.window.first) continue;
      const part = await fetchLines(name, wanted);
      if (state.program === name) showWindow(part);
    }
  } catch (_) { /* shown on the message line */ } finally {
    lines.loading = false;
  }
  if (scrollTo !== null) $("#program-text").children[scrollTo - lines.window.first]?.scrollIntoView({ block: "center" });
}

// Paging by hand stops the window from following the running program; "current" (or
// opening a program) makes it follow again.
export const windowFirst = () => (lines.window ? lines.window.first : 1);
const browse = (first, scrollTo = null) => { lines.follow = false; return goToLine(first, scrollTo); };
$("#lines-first").addEventListener("click", () => browse(1));
$("#lines-previous").addEventListener("click", () => browse(windowFirst() - WINDOW_LINES));
$("#lines-next").addEventListener("click", () => browse(windowFirst() + WINDOW_LINES));
$("#lines-last").addEventListener("click", () => browse(lines.window ? lines.window.total : 1));
$("#lines-current").addEventListener("click", () => {
  lines.follow = true;
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
  const shown = lines.window;
  if (!shown || lines.loading) return;
  const half = WINDOW_LINES / 2;
  if (list.scrollTop + list.clientHeight >= list.scrollHeight - 2 && shown.first + shown.lines.length - 1 < shown.total) {
    goToLine(shown.first + half, shown.first + shown.lines.length - 1);
  } else if (list.scrollTop <= 0 && shown.first > 1) {
    goToLine(shown.first - half, shown.first);
  }
});
