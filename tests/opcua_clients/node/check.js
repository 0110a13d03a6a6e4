// node-opcua's client, unmodified, against cnc-service's OPC UA front end.
//
//   node check.js <check> <endpoint url>
//
// One check per process; the last line of stdout is JSON: {"ok": true, "result": ...}
// or {"ok": false, "error": "..."}. Checks:
//   browse_read  browse everything below Objects (hierarchical references, forward),
//                read the Value of every variable found; result: node and variable
//                counts, the browse names of the top level, the variables whose read was
//                not Good (status names), and the values of a few CncInterface members.
"use strict";

const {
    OPCUAClient, MessageSecurityMode, SecurityPolicy, AttributeIds, BrowseDirection,
    NodeClass, resolveNodeId, StatusCodes,
} = require("node-opcua-client");

const READ_CHUNK = 500; // values per Read request: below the server's limits

async function browseAll(session) {
    const seen = new Set();
    const variables = [];
    const names = new Map(); // nodeId -> browse path text
    let frontier = [{ nodeId: resolveNodeId("ObjectsFolder"), path: "Objects" }];
    seen.add(frontier[0].nodeId.toString());
    const top = [];
    while (frontier.length > 0) {
        const results = await session.browse(frontier.map((item) => ({
            nodeId: item.nodeId, browseDirection: BrowseDirection.Forward,
            referenceTypeId: "HierarchicalReferences", includeSubtypes: true,
            nodeClassMask: 0, resultMask: 63,
        })));
        const next = [];
        for (let k = 0; k < results.length; k++) {
            const result = results[k];
            if (!result.statusCode.equals(StatusCodes.Good)) {
                throw new Error(`browse of ${frontier[k].path}: ${result.statusCode.name}`);
            }
            for (const ref of result.references || []) {
                const id = ref.nodeId.toString();
                if (seen.has(id)) continue;
                seen.add(id);
                const path = `${frontier[k].path}/${ref.browseName.name}`;
                names.set(id, path);
                if (frontier[k].path === "Objects") top.push(ref.browseName.name);
                if (ref.nodeClass === NodeClass.Variable) variables.push(ref.nodeId);
                next.push({ nodeId: ref.nodeId, path });
            }
        }
        frontier = next;
    }
    return { count: seen.size, variables, names, top };
}

async function browseRead(session) {
    const found = await browseAll(session);
    const bad = [];
    const samples = {};
    for (let start = 0; start < found.variables.length; start += READ_CHUNK) {
        const chunk = found.variables.slice(start, start + READ_CHUNK);
        const values = await session.read(chunk.map((nodeId) => ({
            nodeId, attributeId: AttributeIds.Value,
        })));
        values.forEach((dv, k) => {
            const path = found.names.get(chunk[k].toString());
            if (!dv.statusCode.isGood()) {
                bad.push(`${path}: ${dv.statusCode.name}`);
            } else if (/CncInterface\/.*\/(ActPos|ActStatus|ActOverride)$/.test(path)) {
                const v = dv.value.value;
                samples[path] = typeof v === "bigint" ? Number(v) : v;
            }
        });
    }
    return { nodes: found.count, variables: found.variables.length, top: found.top.sort(),
             bad, samples };
}

async function main() {
    const [check, endpoint] = process.argv.slice(2);
    const client = OPCUAClient.create({
        applicationName: "cnc-objects node-opcua check",
        endpointMustExist: false,
        securityMode: MessageSecurityMode.None,
        securityPolicy: SecurityPolicy.None,
        connectionStrategy: { maxRetry: 2, initialDelay: 200, maxDelay: 1000 },
    });
    await client.connect(endpoint);
    const session = await client.createSession();
    try {
        if (check !== "browse_read") throw new Error(`unknown check ${check}`);
        return await browseRead(session);
    } finally {
        await session.close();
        await client.disconnect();
    }
}

main().then(
    (result) => { console.log(JSON.stringify({ ok: true, result })); process.exit(0); },
    (error) => { console.log(JSON.stringify({ ok: false, error: String(error && error.stack || error) })); process.exit(0); },
);
