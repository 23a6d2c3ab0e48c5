"""Emission: straight-line programs printed as C99 through the jinja2 templates."""
