"""The files of the OPC UA front end's security, as ``cnc opcua-cert`` writes them into a
directory and the service reads them from there (``[opcua] certificate_dir``;
docs/opcua.md, "Security"). Names only: no I/O here."""

from __future__ import annotations

CERTIFICATE_FILE = "server-cert.der"  # the application certificate, DER (OPC 10000-6 6.2.2)
PRIVATE_KEY_FILE = "server-key.pem"  # its RSA private key, PKCS#8 PEM, mode 0600
TRUSTED_DIR = "trusted"  # certificates (DER or PEM) of the clients that may connect
DEFAULT_CERTIFICATE_DIR = "cnc-data/opcua"  # beside make run's program store
CERTIFICATE_DAYS = 3650  # how long a certificate of cnc opcua-cert is valid by default
