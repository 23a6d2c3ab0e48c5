"""Independent oracles for dyngen's tests (no imports from the dyngen package)."""
