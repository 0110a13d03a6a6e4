"""The names of CURVE key files, as ``cnc keys new`` writes them and a client finds them
(docs/security.md); a module of their own, without zmq, for the commands that only name
files."""

PUBLIC_SUFFIX = ".key"
SECRET_SUFFIX = ".key_secret"
SERVER_KEY_FILE = "server.key"  # the service's public key, beside a client's key by default
