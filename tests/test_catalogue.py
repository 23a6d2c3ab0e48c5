"""Every function of the catalogue (dyngen.catalogue) is emitted, declared and documented in
the header, listed in the manifest with its shapes, wrapped in the Eigen header and checked
by the self-test; and nothing else is emitted. Read from the checked-in generated/lwr (kept
current by test_cli's regeneration test)."""

from __future__ import annotations

import json
import re

from conftest import ROOT

from dyngen import catalogue

FOLDER = ROOT / "generated" / "lwr"
P = "lwr"


def manifest():
    return json.loads((FOLDER / "manifest.json").read_text())


def dims():
    m = manifest()
    ranks = {kind: m["coefficients"][kind]["rank"] for kind in catalogue.KINDS}
    return catalogue.dimensions(m["dof"], ranks, len(m["gravity_symbols"]))


def test_every_catalogue_function_is_defined_in_its_source_and_nothing_else():
    defined = {}
    for source in FOLDER.glob(f"{P}_*.c"):
        if source.name == f"{P}_selftest.c":
            continue
        for name in re.findall(rf"^void {P}_(\w+)\(", source.read_text(), re.M):
            defined[name] = source.name
    assert defined == {f.name: f"{P}_{f.source}.c" for f in catalogue.FUNCTIONS}


def test_every_catalogue_function_is_declared_and_documented_in_the_header():
    header = (FOLDER / f"{P}.h").read_text()
    sizes = dims()
    for f in catalogue.FUNCTIONS:
        args = ", ".join([f"const {P}_real *{a}" for a in f.arguments(sizes["gravity_symbols"] > 0)] +
                         [f"{P}_real *{o.name}" for o in f.outputs])
        declaration = f"void {P}_{f.name}({args});"
        assert declaration in header, declaration
        comment = header[:header.index(declaration)].rsplit("/*", 1)[1]
        # straight-line functions carry the catalogue's text; friction (its own template) its law
        assert f.doc in comment if f.model != "template" else f.name in comment, (f.name, comment)


def test_every_catalogue_function_is_in_the_manifest_with_its_shapes():
    sizes = dims()
    listed = {entry["name"]: entry for entry in manifest()["functions"]}
    assert sorted(listed) == sorted(f"{P}_{f.name}" for f in catalogue.FUNCTIONS)
    for f in catalogue.FUNCTIONS:
        entry = listed[f"{P}_{f.name}"]
        assert [i["name"] for i in entry["inputs"]] == list(f.arguments(sizes["gravity_symbols"] > 0))
        for i in entry["inputs"]:
            shape = catalogue.ARGUMENTS[i["name"]].shape
            assert i["length"] == sizes[shape[0]] * (sizes[shape[1]] if len(shape) > 1 else 1)
        assert entry["output"]["name"] == f.output.name
        assert entry["output"]["shape"] == [sizes[d] for d in f.output.shape]
        assert [(o["name"], o["shape"]) for o in entry["outputs"]] == [(o.name, [sizes[d] for d in o.shape])
                                                                       for o in f.outputs]


def test_every_catalogue_function_has_an_eigen_wrapper():
    hpp = (FOLDER / f"{P}.hpp").read_text()
    for f in catalogue.FUNCTIONS:
        assert f"inline void {f.name}(" in hpp and f"{P}_{f.name}(detail::in<" in hpp, f.name
        assert all(f"using {o.eigen} = " in hpp for o in f.outputs)


def test_every_catalogue_function_is_checked_by_the_selftest():
    selftest = (FOLDER / f"{P}_selftest.c").read_text()
    for f in catalogue.FUNCTIONS:
        call = re.search(rf"^\s+{P}_{f.name}\((.*)\);$", selftest, re.M)
        assert call, f.name
        label = f.name if not f.check.times else f"{f.name} * {f.check.times}"
        labels = [f"{f.name}.{o.name}" for o in f.outputs] if f.more else [label]
        assert all(f'check("{x}"' in selftest or f'compare("{x}"' in selftest for x in labels), f.name
        assert f"{f.expected}_expected" in selftest
    expected = manifest()["selftest"]
    assert sorted(expected["expected"]) == sorted(f.name for f in catalogue.FUNCTIONS
                                                   if not f.state and not f.check.expected)
