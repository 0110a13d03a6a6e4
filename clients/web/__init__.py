"""cnc-web: the web HMI (docs/web.md)."""
