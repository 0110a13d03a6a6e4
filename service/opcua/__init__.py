"""The OPC UA front end (OPC 40502 CNC, on asyncua): the third front end beside ZeroMQ and
ADS, over the same backend, notification hub and access policy (docs/opcua.md).

Importing this package imports nothing of asyncua; ``server`` does."""
