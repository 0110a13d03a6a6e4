"""The endpoint a client dials when given none, in a module of its own: ``cnc`` names it in
its help without importing the client library (zmq, asyncio)."""

DEFAULT_ENDPOINT = "tcp://127.0.0.1:5555"  # the service's default (cnc-service --endpoint)
