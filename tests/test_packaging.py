"""A non-editable install (pip install .) must carry the templates and the static extractor
driver: they are package data (generator/dyngen/templates/, generator/dyngen/extraction/driver_cpp/), one
real place each, declared in pyproject's package-data."""

import tomllib
from pathlib import Path

from dyngen.emission import render

ROOT = Path(__file__).resolve().parents[1]


def test_templates_are_one_real_folder_of_the_package():
    package_templates = ROOT / "generator" / "dyngen" / "templates"
    assert render.TEMPLATES == package_templates and not package_templates.is_symlink()
    assert not any(p.is_symlink() for p in package_templates.rglob("*"))
    assert [p.name for p in (ROOT / "templates").iterdir()] == ["README.md"]  # a pointer only


def test_every_template_is_declared_as_package_data():
    globs = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["dyngen"]
    package = ROOT / "generator" / "dyngen"
    shipped = {p.resolve() for g in globs for p in package.glob(g)}  # setuptools' glob: * stays in one folder
    templates = [p.resolve() for folder in ("templates", "extraction/driver_cpp") for p in (package / folder).rglob("*")
                 if p.is_file()]
    assert templates
    missing = [str(t) for t in templates if t not in shipped]
    assert not missing, f"templates not shipped in the wheel (add them to package-data): {missing}"
