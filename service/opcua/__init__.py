"""The OPC UA front end (asyncua): OPC 40501-1 MachineTool and OPC 40502 CNC over the same
backend, notification hub and access policy as ZeroMQ and ADS (docs/opcua.md)."""
