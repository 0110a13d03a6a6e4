// cnc-web: the tool path of the program page (XY): the planned path, the path run so far
// and the tool, on equal scales with axes and a grid in mm, in workpiece coordinates while
// an offset is in effect. The path run so far is recorded every frame whatever page is
// shown (cheap); it is drawn only on the program page.

import { $, currentXY, setAttr, state, v, working } from "./core.js";
import { onChannel, onEveryFrame } from "./router.js";

const LIVE_POINTS_MAX = 5000;  // the oldest points of a longer run are dropped,
const LIVE_POINTS_KEPT = 4000; // a thousand at a time (the polyline is redrawn then)
const path = {
  planned: null,  // {x: [], y: []} of the planned tool path (machine coordinates)
  live: [],       // [x, y] machine positions of the tool while a program runs
  extent: null,   // [minX, minY, maxX, maxY] of the view: grows, never shrinks
  extentKey: null,
  gridKey: null,
  drawn: { view: null, planned: null, live: null, liveCount: 0, liveText: "" }, // polylines drawn
};

// What lies between machine and workpiece coordinates now (zero offset and tool
// length: machine - workpiece), and the name of the coordinates the path is drawn in.
export function pathFrame() {
  const acs = currentXY("acs");
  const pcs = currentXY("pcs");
  const shift = acs && pcs ? [acs[0] - pcs[0], acs[1] - pcs[1]] : [0, 0];
  const group = v(`ch${state.channel}.mc_active_zero_offset_r`) || 0;
  const workpiece = group !== 0 || shift[0] !== 0 || shift[1] !== 0;
  return { shift, name: workpiece ? `workpiece coordinates (G${53 + group})` : "machine coordinates (G53)" };
}

function recordLivePath() {
  const here = currentXY();
  if (!here || !working()) return;
  const last = path.live[path.live.length - 1];
  if (!last || last[0] !== here[0] || last[1] !== here[1]) {
    path.live.push(here);
    if (path.live.length > LIVE_POINTS_MAX) path.live = path.live.slice(-LIVE_POINTS_KEPT);
  }
}
onEveryFrame(recordLivePath);

// A new run, or another channel: the path so far starts anew.
export function clearLive() {
  path.live = [];
}

// Another program: no planned path yet, and the view starts anew.
export function clearPlanned() {
  path.planned = null;
  path.extent = null;
}

export function setPlanned(trace) {
  const [xName, yName] = Object.keys(trace.positions_mm);
  path.planned = { x: trace.positions_mm[xName] || [], y: trace.positions_mm[yName] || [] };
  path.extent = null;
  drawPath();
}

onChannel(() => {
  path.live = [];
  path.extent = null;
});

function niceStep(span) {
  const rough = span / 5;
  const power = 10 ** Math.floor(Math.log10(rough));
  return [1, 2, 5, 10].map((f) => f * power).find((step) => step >= rough);
}

const PLOT = { left: 46, top: 10, width: 344, height: 262 }; // inside the 400 x 300 view box

export function drawPath() {
  const frame = pathFrame();
  const [dx, dy] = frame.shift;
  const toView = ([x, y]) => [x - dx, y - dy];
  const planned = path.planned ? path.planned.x.map((x, k) => toView([x, path.planned.y[k]])) : [];
  const live = path.live.map(toView);
  const acs = currentXY();
  const here = acs ? toView(acs) : null;
  // The view holds the planned path from the start and grows when the tool leaves it:
  // it never shrinks to the path so far. A new offset (G53 -> G54) starts it anew.
  const key = `${dx},${dy}`;
  let e = path.extentKey === key ? path.extent : null;
  for (const [x, y] of planned.concat(live, here ? [here] : [])) {
    e = e ? [Math.min(e[0], x), Math.min(e[1], y), Math.max(e[2], x), Math.max(e[3], y)] : [x, y, x, y];
  }
  if (!e) return;
  path.extent = e;
  path.extentKey = key;
  const span = Math.max((e[2] - e[0]) * PLOT.height / PLOT.width, e[3] - e[1], 1) * 1.1;
  const scale = PLOT.height / span; // px per mm, the same on both axes
  const [cx, cy] = [(e[0] + e[2]) / 2, (e[1] + e[3]) / 2];
  const sx = (x) => PLOT.left + PLOT.width / 2 + (x - cx) * scale;
  const sy = (y) => PLOT.top + PLOT.height / 2 - (y - cy) * scale;
  drawGrid(frame.name, scale, cx, cy, sx, sy);
  const point = ([x, y]) => `${sx(x).toFixed(2)},${sy(y).toFixed(2)}`;
  // The polylines are drawn again only when the view or the path changed; a path run
  // further in the same view only gets its new points.
  const drawn = path.drawn;
  const view = `${key} ${scale} ${cx} ${cy}`;
  if (drawn.view !== view || drawn.planned !== path.planned) {
    $("#path-planned").setAttribute("points", planned.map(point).join(" "));
    drawn.planned = path.planned;
  }
  const liveBefore = drawn.liveText;
  if (drawn.view !== view || drawn.live !== path.live || live.length < drawn.liveCount) {
    drawn.liveText = live.map(point).join(" ");
  } else if (live.length > drawn.liveCount) {
    const more = live.slice(drawn.liveCount).map(point).join(" ");
    drawn.liveText = drawn.liveText ? `${drawn.liveText} ${more}` : more;
  }
  drawn.view = view;
  drawn.live = path.live;
  drawn.liveCount = live.length;
  if (drawn.liveText !== liveBefore) {
    $("#path-live").setAttribute("points", drawn.liveText);
  }
  if (here) {
    setAttr($("#path-tool"), "cx", sx(here[0]).toFixed(2));
    setAttr($("#path-tool"), "cy", sy(here[1]).toFixed(2));
  }
}

// The axes, the grid and its labels in mm: drawn again only when the view changes.
function drawGrid(frameName, scale, cx, cy, sx, sy) {
  const key = `${frameName} ${scale} ${cx} ${cy}`;
  if (path.gridKey === key) return;
  path.gridKey = key;
  const step = niceStep(PLOT.width / scale);
  const [x0, x1] = [cx - PLOT.width / 2 / scale, cx + PLOT.width / 2 / scale];
  const [y0, y1] = [cy - PLOT.height / 2 / scale, cy + PLOT.height / 2 / scale];
  const digits = step < 1 ? Math.ceil(-Math.log10(step)) : 0;
  const parts = [];
  const bottom = PLOT.top + PLOT.height;
  for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
    const px = sx(x).toFixed(1);
    parts.push(`<line class="${Math.abs(x) < step / 1e6 ? "axis" : "tick"}" x1="${px}" y1="${PLOT.top}" x2="${px}" y2="${bottom}"/>`,
      `<text x="${px}" y="${bottom + 12}" text-anchor="middle">${x.toFixed(digits)}</text>`);
  }
  for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
    const py = sy(y).toFixed(1);
    parts.push(`<line class="${Math.abs(y) < step / 1e6 ? "axis" : "tick"}" x1="${PLOT.left}" y1="${py}" x2="${PLOT.left + PLOT.width}" y2="${py}"/>`,
      `<text x="${PLOT.left - 4}" y="${py}" text-anchor="end" dominant-baseline="middle">${y.toFixed(digits)}</text>`);
  }
  parts.push(`<rect class="frame" x="${PLOT.left}" y="${PLOT.top}" width="${PLOT.width}" height="${PLOT.height}"/>`,
    `<text class="axis-name" x="${PLOT.left + PLOT.width - 2}" y="${bottom - 4}" text-anchor="end">X mm</text>`,
    `<text class="axis-name" x="${PLOT.left + 4}" y="${PLOT.top + 12}">Y mm</text>`);
  $("#path-grid").innerHTML = parts.join("");
  $("#path-frame").textContent = `· ${frameName}`;
  $("#path-scale").textContent = `grid ${step.toFixed(digits)} mm`;
}
