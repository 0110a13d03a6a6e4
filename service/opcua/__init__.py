"""The OPC UA front end (asyncua): OPC 40501-1 MachineTool and OPC 40502 CNC, the third front
end beside ZeroMQ and ADS, over the same backend, notification hub and access policy
(docs/opcua.md).

Importing this package imports nothing of asyncua; ``server`` does."""
