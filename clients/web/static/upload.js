// cnc-web: uploads to the program store. A program goes in slices of the File (never read
// whole into the page): each slice is one request that cnc-web forwards to the service's
// chunked upload as it arrives. The bar shows what cnc-web received; Cancel (or a closed
// tab) abandons the upload.

import { $, api, say, sizeText, state } from "./core.js";

let running = null;  // {id, name, controller, cancelled} of the upload under way

// Upload ``files`` one after the other, then ``uploaded(names)``.
async function upload(files, uploaded) {
  for (const file of files) {
    try {
      await uploadFile(file);
      say(`uploaded ${file.name} (${sizeText(file.size)})`);
    } catch (error) {
      say(running && running.cancelled ? `upload of ${file.name} cancelled` : error.message, true);
      return;
    } finally {
      running = null;
      $("#upload").hidden = true;
      $("#upload-input").value = "";
    }
  }
  await uploaded(files.map((file) => file.name));
}

async function uploadFile(file) {
  if (running) throw new Error(`an upload (${running.name}) is under way: wait for it or cancel it`);
  running = { id: null, name: file.name, controller: new AbortController(), cancelled: false };
  const mine = running;
  const started = performance.now();
  const progress = (received) => {
    const s = (performance.now() - started) / 1000;
    $("#upload-progress").value = file.size ? received / file.size : 1;
    $("#upload-status").textContent = `${file.name}: ${sizeText(received)} of ${sizeText(file.size)} ` +
      `(${file.size ? Math.floor(received / file.size * 100) : 100} %)` + (s > 0.5 ? ` · ${(received / 1e6 / s).toFixed(1)} MB/s` : "");
  };
  progress(0);
  $("#upload").hidden = false;
  const opened = await api("POST", "/api/uploads", { name: file.name, size_bytes: file.size }, true);
  mine.id = opened.upload;
  let at = 0;
  while (at < file.size) {
    const response = await fetch(`/api/uploads/${opened.upload}?at=${at}`, {
      method: "PUT", body: file.slice(at, at + opened.slice_bytes), credentials: "same-origin",
      headers: { "X-CSRF-Token": state.session.csrf, "Content-Type": "application/octet-stream" },
      signal: mine.controller.signal,
    });
    let data = {};
    try { data = await response.json(); } catch (_) { data = {}; }
    if (!response.ok) throw new Error(data.error || `${response.status} ${response.statusText}`);
    at = data.received_bytes;
    progress(at);
  }
  await api("POST", `/api/uploads/${opened.upload}/commit`, {}, true);
}

// The file input and the drop box upload; ``uploaded(names)`` follows each upload.
export function takeUploads(uploaded) {
  $("#upload-cancel").addEventListener("click", async () => {
    const cancelled = running;
    if (!cancelled) return;
    cancelled.cancelled = true;
    cancelled.controller.abort();  // a slice on its way is dropped: cnc-web abandons the upload
    if (cancelled.id) await api("DELETE", `/api/uploads/${cancelled.id}`, undefined, true).catch(() => {});
  });
  $("#upload-input").addEventListener("change", (event) => upload([...event.target.files], uploaded));
  const drop = $("#drop");
  drop.addEventListener("dragover", (event) => { event.preventDefault(); drop.classList.add("over"); });
  drop.addEventListener("dragleave", () => drop.classList.remove("over"));
  drop.addEventListener("drop", (event) => {
    event.preventDefault();
    drop.classList.remove("over");
    if (state.session.may_upload) upload([...event.dataTransfer.files], uploaded);
    else say(`role ${state.session.role} may not upload programs; admin may`, true);
  });
}
