"""Independent simulators the twin is validated against (see rigs/README.md)."""
