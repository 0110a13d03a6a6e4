"""The running system: configuration, kernel, binding, ZeroMQ server, entry point."""

__version__ = "0.1.0"
