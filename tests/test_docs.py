"""The README and docs/ as a newcomer uses them: every command they show runs (its --help at
least, with every option it uses known to that --help), every file a command names exists, and
every relative link resolves (files, and #anchors to headings)."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", ROOT / "BENCHMARKS.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```[a-z]*\n(.*?)^```", re.S | re.M)
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
PROGRAMS = ("dyngen ", "python3 -m dyngen", "python bench/", "python3 bench/")


def _commands(page: Path) -> list[str]:
    """Command lines in the page's code blocks (fenced or indented), prompt and comment removed."""
    text = page.read_text()
    blocks = [m.group(1) for m in FENCE.finditer(text)]
    blocks += [line[4:] for line in text.splitlines() if line.startswith("    ") and not line.startswith("     ")]
    blocks += re.findall(r"(?<!`)`([^`\n]+)`(?!`)", FENCE.sub("", text))  # inline code
    lines = []
    for block in blocks:
        for line in block.splitlines():
            line = line.strip().removeprefix("$ ")
            line = line.split("  #")[0].split(" # ")[0].strip()
            for part in re.split(r"\s*(?:&&|\|\|?|;)\s*", line):
                words = part.split()
                if part.startswith(PROGRAMS) and not any(w.endswith(":") for w in words[:2]):  # not output
                    lines.append(part)
    return lines


ALL = sorted({(page.relative_to(ROOT).as_posix(), c) for page in PAGES for c in _commands(page)})


@lru_cache(maxsize=None)
def _help(argv: tuple) -> str:
    run = subprocess.run([sys.executable, *argv, "--help"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, f"{' '.join(argv)} --help failed: {run.stderr[-500:]}"
    return run.stdout


def _program(words: list[str]) -> tuple[tuple, list[str]]:
    """(the argv that runs the program and its subcommand, the rest)."""
    if words[0] == "dyngen":
        words = ["-m", "dyngen", *words[1:]]
    elif words[:3] == ["python3", "-m", "dyngen"]:
        words = words[1:]
    else:  # python bench/x.py
        return (words[1],), words[2:]
    # a subcommand, or the main job (whose options --help lists once it is given the robot file)
    sub = words[2:3] if len(words) > 2 and not words[2].startswith("-") else []
    return (*words[:2], *sub), words[2 + len(sub):]


def test_the_pages_show_commands():
    assert len(ALL) >= 10, ALL


@pytest.mark.parametrize("page, command", ALL)
def test_every_command_shown_runs_and_knows_its_options(page, command):
    words = [w for w in shlex.split(command.replace("[", " ").replace("]", " ")) if w not in ("...", "|")]
    argv, rest = _program(words)
    text = _help(argv)
    for word in rest:
        option = word.split("=")[0]
        if option.startswith("--"):
            assert option in text, f"{page}: `{command}` uses {option}, unknown to `{' '.join(argv)} --help`"
        elif "/" in word and not word.startswith("-") and word.split("/")[0] in ("examples", "generated", "bench"):
            assert (ROOT / word).exists(), f"{page}: `{command}` names {word}, which does not exist"


def _anchors(page: Path) -> set[str]:
    """GitHub's heading anchors: lowercase, punctuation dropped, spaces as hyphens."""
    heads = re.findall(r"^#+ (.*)$", page.read_text(), re.M)
    return {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-") for h in heads}


LINKS = sorted({(page.relative_to(ROOT).as_posix(), a or b) for page in PAGES
                for a, b in LINK.findall(page.read_text()) if not (a or b).startswith(("http", "mailto:"))})


@pytest.mark.parametrize("page, target", LINKS)
def test_every_relative_link_resolves(page, target):
    source = ROOT / page
    path, _, anchor = target.partition("#")
    resolved = (source.parent / path).resolve() if path else source
    assert resolved.exists(), f"{page}: link to {target}: no such file"
    if anchor and resolved.suffix == ".md":
        assert anchor in _anchors(resolved), f"{page}: link to {target}: no such heading"


def test_the_readme_c_example_compiles_and_runs(tmp_path):
    """The README's C (its ```c block) against generated/lwr, strict C99, and it runs."""
    blocks = re.findall(r"^```c\n(.*?)^```", (ROOT / "README.md").read_text(), re.S | re.M)
    assert len(blocks) == 1
    folder = ROOT / "generated" / "lwr"
    (tmp_path / "example.c").write_text(blocks[0])
    sources = [str(p) for p in sorted(folder.glob("lwr_*.c")) if p.name != "lwr_selftest.c"]
    exe = tmp_path / "example"
    subprocess.run(["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1", "-I", str(folder),
                    str(tmp_path / "example.c"), *sources, "-lm", "-o", str(exe)], check=True, timeout=300)
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0 and run.stdout.startswith("tau1 = "), run.stdout + run.stderr
    tau1, qdd1 = (float(x.split("=")[1]) for x in run.stdout.strip().split(","))
    assert abs(qdd1) < 1e-9 * max(1.0, abs(tau1))  # FD(ID(0)) = 0: the forward dynamics undoes the rnea
