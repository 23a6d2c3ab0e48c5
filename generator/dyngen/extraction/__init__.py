"""Extraction: physically consistent link parameters from identified coefficients."""
