// One check of jisotalo's ads-client (npm, used unmodified) against cnc-service, on a
// fresh connection: `node check.js CHECK HOST PORT NETID`. Prints one JSON line with what
// the client saw; tests/e2e/test_ads_other_clients.py judges it. Errors are reported with
// the ADS code the client got (adsError.errorCode), never thrown out of here.
'use strict';
const { Client } = require('ads-client');

const [check, host, port, netId] = process.argv.slice(2);

function adsCode(err) {
  for (let e = err; e; e = e.parent) {
    if (e.adsError && e.adsError.errorCode) return e.adsError.errorCode;
  }
  return null;
}

async function refusal(promise) {
  try {
    await promise;
    return { code: 0 };
  } catch (err) {
    return { code: adsCode(err), message: err.message };
  }
}

function waitFor(predicate, timeoutMs, what) {
  return new Promise((resolve, reject) => {
    const started = Date.now();
    const poll = () => {
      if (predicate()) return resolve();
      if (Date.now() - started > timeoutMs) return reject(new Error(`timed out waiting for ${what}`));
      setTimeout(poll, 5);
    };
    poll();
  });
}

const CHECKS = {
  async by_name(c) {
    const override = (await c.readValue('ch1.mc_command_feed_override_r')).value;
    await c.writeValue('gpCh[0].contour_lookahead.request.length', 12.5);
    const length = (await c.readValue('gpCh[0].contour_lookahead.request.length')).value;
    const text = (await c.readValue('cnc_version_r')).value;
    return { override, length, text };
  },
  async handles(c) {
    const handle = await c.createVariableHandle('gpCh[0]^.contour_lookahead.request.start_position');
    await c.writeRawByHandle(handle, Buffer.from(new Float64Array([4.25]).buffer));
    const raw = await c.readRawByHandle(handle);
    await c.deleteVariableHandle(handle);
    const multi = await c.createVariableHandleMulti(['ch1.mc_command_feed_override_r', 'no.such.symbol']);
    return {
      handle: { size: handle.size, dataType: handle.dataType },
      value: raw.readDoubleLE(0),
      multi: multi.map((m) => ({ success: m.success, code: m.errorCode, dataType: m.handle && m.handle.dataType })),
    };
  },
  async structs(c) {
    await c.writeValue('gpCh[0].contour_lookahead.request', { start_position: 3, length: 7 });
    const request = (await c.readValue('gpCh[0].contour_lookahead.request')).value;
    const suspend = (await c.readValue('gpCh[0]^.bahn_mc_control.suspend_axis_output')).value;
    const axes = (await c.readValue('gpAx')).value;
    const blocks = (await c.readValue('gpCh[1].contour_lookahead.response.block')).value;
    // nothing in state is writable: other bytes than its own are refused (autoFill: the
    // padding members the type lists come from the struct as read)
    const readOnly = await refusal(c.writeValue('gpCh[0].contour_lookahead.state',
      { max_dist_prog_start: 0, count_logged_blocks: 7, f_log_is_active: false }, true));
    // Node-RED's write node: one member of a struct whose first member is read-only,
    // the rest filled from the struct as read (issue 41: 0x704 before)
    const spindleWrite = await refusal(c.writeValue('gpCh[0].spindle', { override_w: 500 }, true));
    const spindle = (await c.readValue('gpCh[0].spindle')).value;
    await c.writeValue('gpCh[0].spindle.override_w', 1000);
    return {
      request, suspend, axisNumbers: axes.map((a) => a.head.log_ax_n_r), blocks: blocks.length,
      blockKeys: Object.keys(blocks[0]), readOnly, spindleWrite,
      spindle: { mode_r: spindle.mode_r, override_w: spindle.override_w },
    };
  },
  async notifications(c) {
    const seen = { leaf: [], struct: [] };
    const leaf = await c.subscribeValue('gpCh[0].contour_lookahead.request.length',
      (d) => seen.leaf.push(d.value), 10);
    const whole = await c.subscribeValue('gpCh[0].contour_lookahead.request',
      (d) => seen.struct.push(d.value), 10);
    await waitFor(() => seen.leaf.length > 0 && seen.struct.length > 0, 10000, 'the first samples');
    await c.writeValue('gpCh[0].contour_lookahead.request.length', 99.5);
    await waitFor(() => seen.leaf.includes(99.5) && seen.struct.some((s) => s.length === 99.5),
      10000, 'the changed samples');
    await leaf.unsubscribe();
    await whole.unsubscribe();
    return { leaf: seen.leaf[seen.leaf.length - 1], struct: seen.struct[seen.struct.length - 1] };
  },
  async sum(c) {
    const names = ['ch1.mc_command_feed_override_r', 'gpCh[0].contour_lookahead.request'];
    const symbols = await Promise.all(names.map((n) => c.getSymbol(n)));
    const reads = await c.readRawMulti(symbols.map((s) => ({ indexGroup: s.indexGroup, indexOffset: s.indexOffset, size: s.size })));
    const writeSymbol = await c.getSymbol('gpCh[0].contour_lookahead.request.start_position');
    const readOnlySymbol = await c.getSymbol('ch1.mc_command_feed_override_r');
    const writes = await c.writeRawMulti([
      { indexGroup: writeSymbol.indexGroup, indexOffset: writeSymbol.indexOffset, value: Buffer.from(new Float64Array([8.5]).buffer) },
      { indexGroup: readOnlySymbol.indexGroup, indexOffset: readOnlySymbol.indexOffset, value: Buffer.from([1, 0]) },
    ]);
    const byName = await c.readWriteRawMulti([
      { indexGroup: 0xF004, indexOffset: 0, size: 0xFFFF, value: Buffer.from('ch1.mc_command_feed_override_r\0') },
      { indexGroup: 0xF004, indexOffset: 0, size: 0xFFFF, value: Buffer.from('no.such.symbol\0') },
    ]);
    return {
      reads: reads.map((r) => ({ success: r.success, size: r.value && r.value.length })),
      writes: writes.map((w) => w.errorCode),
      startPosition: (await c.readValue('gpCh[0].contour_lookahead.request.start_position')).value,
      byName: byName.map((r) => ({ code: r.errorCode, data: r.data ? [...r.data] : null })),
    };
  },
  async upload_read_all(c) {
    const started = Date.now();
    const symbols = await c.getSymbols();
    const failed = [];
    let read = 0;
    for (const name of Object.keys(symbols)) {
      try {
        await c.readValue(name);
        read += 1;
      } catch (err) {
        failed.push({ name, code: adsCode(err), message: err.message });
      }
    }
    return { count: Object.keys(symbols).length, read, failed, seconds: (Date.now() - started) / 1000 };
  },
  async unknown_name(c) {
    return {
      read: await refusal(c.readValue('gpCh[0].no_such_member')),
      handle: await refusal(c.createVariableHandle('no.such.symbol')),
      symbol: await refusal(c.getSymbol('no.such.symbol')),
    };
  },
  async read_only_write(c) {
    return {
      leaf: await refusal(c.writeValue('ch1.mc_command_feed_override_r', 5)),
      stillThere: (await c.readValue('ch1.mc_command_feed_override_r')).value,
    };
  },
  async reads_per_second(c) {
    // Bench: by-name reads on this fresh connection for 2 s (`make bench` part ads).
    const until = Date.now() + 2000;
    let count = 0;
    while (Date.now() < until) {
      await c.readValue('ch1.mc_command_feed_override_r');
      count += 1;
    }
    return { readsPerSecond: count / 2 };
  },
};

// `registered`: no local AMS address given, so ads-client asks the router for one (AMS/TCP
// port connect) as on a PC with TwinCAT; what it got, a read, and the port close on
// disconnect (the router ends the connection then).
const REGISTERED = {
  async registered(c) {
    const { localAmsNetId, localAdsPort } = c.connection;
    const override = (await c.readValue('ch1.mc_command_feed_override_r')).value;
    const started = Date.now();
    await c.disconnect();
    return { localAmsNetId, localAdsPort, override, disconnectMs: Date.now() - started };
  },
};

async function main() {
  const own = check in REGISTERED ? {}
    : { localAmsNetId: '127.0.0.1.1.31', localAdsPort: 30000 + (process.pid % 30000) };
  const c = new Client({
    targetAmsNetId: netId, targetAdsPort: 851, routerAddress: host, routerTcpPort: Number(port),
    ...own, timeoutDelay: 10000, autoReconnect: false, hideConsoleWarnings: true,
  });
  let out;
  try {
    await c.connect();
    out = { ok: true, result: await (CHECKS[check] || REGISTERED[check])(c) };
  } catch (err) {
    out = { ok: false, code: adsCode(err), error: String(err && err.stack || err) };
  }
  await c.disconnect().catch(() => {});
  process.stdout.write(JSON.stringify(out) + '\n');
}

main();
