"""The ADS front end: AMS/TCP connections, routes, the symbol table and file services.

TwinCAT's wire (docs/ads.md) over the same dispatcher as the ZeroMQ front end.
"""
