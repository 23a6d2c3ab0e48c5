"""The extraction driver's template is one top file that includes the parts in templates/extract/.

A part left out of extract.cpp.j2 (or named there but missing) would silently drop code from, or
break, the rendered <robot>_extract.cpp; the driver's behaviour is tested in test_extraction.py and
its text against the committed generated/lwr in test_cli.py.
"""

from __future__ import annotations

import re

from conftest import ROOT

TEMPLATES = ROOT / "templates"


def test_every_extract_part_is_included_exactly_once():
    top = (TEMPLATES / "extract.cpp.j2").read_text()
    included = re.findall(r'{%-?\s*include\s+"([^"]+)"', top)
    parts = sorted(f"extract/{p.name}" for p in (TEMPLATES / "extract").iterdir())
    assert parts, "templates/extract/ holds no parts"
    assert sorted(included) == parts, f"included {included}, present {parts}"
    for part in parts:  # parts include nothing themselves: the top file is the whole list
        assert "{% include" not in (TEMPLATES / part).read_text(), part
