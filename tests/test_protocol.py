"""The extractor's problem file (extraction/protocol.py): what the Python writer writes, the
compiled C++ driver reads; `--echo` writes back what it read, and every field, every option
(each changed from its default) among them, comes back unchanged. Every extraction option is
either sent to the driver or used before it (in Python)."""

from __future__ import annotations

import subprocess
from dataclasses import fields

import numpy as np
from conftest import ROOT
from test_options import CHANGED

from dyngen.extraction import driver
from dyngen.extraction.options import Options
from dyngen.extraction.problem import Problem, Stage
from dyngen.extraction.protocol import SCHEMA, problem_text, read_problem_text
from dyngen.extraction.targets import Target
from dyngen.generate import generate

# Options the Python side turns into the problem itself: the stages, the mass bounds, the equalities.
USED_BEFORE_THE_DRIVER = {"procedure", "mass_margin", "identities"}


def test_every_option_reaches_the_driver_or_is_used_before_it():
    sent = {f.key for f in SCHEMA}
    for f in fields(Options):
        assert (f.name in sent) != (f.name in USED_BEFORE_THE_DRIVER), f.name


def random_problem(ranks: dict, n: int):
    rng = np.random.default_rng(5)
    lower = rng.uniform(-1, 0, n)
    problem = Problem(n // 10, lower, lower + rng.uniform(0.1, 1, n), rng.normal(size=n), rng.uniform(1, 2, n),
                      (3.5, 4.25), [[(1.5, [3, 4]), (-2.0, [7])], [(0.25, [0, 0, 1])]], rng.normal(size=n) / 3)
    blocks = [Target("gravity", rng.normal(size=(2, ranks["gravity"])) * 1e-3, rng.normal(size=2)),
              Target("full", rng.normal(size=(3, ranks["full"])), rng.normal(size=3) * 1e5)]
    stage = Stage("joint", blocks, rng.uniform(size=n) > 0.3, rng.normal(size=n),
                  [Target("inertia", rng.normal(size=(1, ranks["inertia"])), rng.normal(size=1))])
    return problem, stage


def test_every_field_round_trips_through_the_driver(tmp_path):
    result = generate(ROOT / "examples" / "lwr.yaml", tmp_path / "gen")
    ranks = {kind: base.rank for kind, base in result.bases.items()}
    n = 10 * result.robot.dof
    problem, stage = random_problem(ranks, n)
    options = Options(**CHANGED)
    text = problem_text(problem, stage, options)
    (tmp_path / "problem.txt").write_text(text)
    exe = driver.build(result.folder)
    subprocess.run([str(exe), "--echo", str(tmp_path / "problem.txt"), str(tmp_path / "echo.txt")], check=True)
    echoed = read_problem_text((tmp_path / "echo.txt").read_text(), ranks)
    written = read_problem_text(text, ranks)
    for field in SCHEMA:
        sent = field.value(problem, stage, options)
        for got in (echoed[field.key], written[field.key]):
            if field.kind in ("blocks",):
                assert [b.kind for b in got] == [b.kind for b in sent]
                for a, b in zip(got, sent):
                    assert np.array_equal(a.W, b.W) and np.array_equal(a.v, b.v), field.key
            elif field.kind in ("reals", "flags"):
                assert np.array_equal(got, np.asarray(sent)), field.key
            elif field.kind == "terms":
                assert got == [[(c, list(idx)) for c, idx in poly] for poly in sent], field.key
            else:
                assert got == sent, field.key
