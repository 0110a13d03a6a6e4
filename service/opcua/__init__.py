"""The OPC UA front end (asyncua): OPC 40501-1 MachineTool and OPC 40502 CNC, the third front
end beside ZeroMQ and ADS, over the same backend, notification hub and access policy
(docs/opcua.md). It runs in a process of its own (``child``), which cnc-service spawns and
serves over a private link (``host``, ``linked_backend``, ``link_frames``).

Importing this package imports nothing of asyncua; ``server`` does (in the child only)."""
