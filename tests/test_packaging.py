"""A non-editable install (pip install .) must carry the templates: they ship in the wheel
through the link generator/dyngen/templates -> templates/ and pyproject's package-data."""

import tomllib
from pathlib import Path

from dyngen.emission import render

ROOT = Path(__file__).resolve().parents[1]


def test_templates_are_found_through_the_package():
    assert render.TEMPLATES.resolve() == (ROOT / "templates").resolve()
    assert (ROOT / "generator" / "dyngen" / "templates").is_symlink()


def test_every_template_is_declared_as_package_data():
    globs = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["dyngen"]
    package = ROOT / "generator" / "dyngen"
    shipped = {p.resolve() for g in globs for p in package.glob(g)}  # setuptools' glob: * stays in one folder
    templates = [p.resolve() for p in (ROOT / "templates").rglob("*") if p.is_file()]
    assert templates
    missing = [str(t) for t in templates if t not in shipped]
    assert not missing, f"templates not shipped in the wheel (add them to package-data): {missing}"
