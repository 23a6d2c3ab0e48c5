"""Derivation: symbolic Newton-Euler, built as straight-line code while it recurses."""
