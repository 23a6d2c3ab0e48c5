"""The extractor's problem file (extraction/protocol.py): what the Python writer writes, the
compiled C++ driver reads; `--echo` writes back what it read, and every field, every option
(each changed from its default) among them, comes back unchanged. Every extraction option is
either sent to the driver or used before it (in Python). The other direction likewise: a result
file with every field (RESULT) comes back unchanged from the driver's generated result reader
and writer (`--echo-result`), and the Python parser (extraction/driver.py) reads each one."""

from __future__ import annotations

import subprocess
from dataclasses import fields

import numpy as np
import pytest
from conftest import ROOT
from test_options import CHANGED

from dyngen.extraction import driver
from dyngen.description.extraction_options import Options
from dyngen.extraction.problem import Problem, Stage
from dyngen.extraction.protocol import RESULT, SCHEMA, problem_text, read_problem_text, read_result_text, result_text
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


@pytest.fixture(scope="module")
def lwr(tmp_path_factory):
    """The LWR generated, and its extractor."""
    result = generate(ROOT / "examples" / "lwr.yaml", tmp_path_factory.mktemp("protocol") / "gen")
    return result, driver.build(result.folder)


def test_every_field_round_trips_through_the_driver(tmp_path, lwr):
    result, exe = lwr
    ranks = {kind: base.rank for kind, base in result.bases.items()}
    n = 10 * result.robot.dof
    problem, stage = random_problem(ranks, n)
    options = Options(**CHANGED)
    text = problem_text(problem, stage, options)
    (tmp_path / "problem.txt").write_text(text)
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


def test_the_result_schema_reads_in_order():
    """Every length and the status a field depends on is read before it."""
    keys = [f.key for f in RESULT]
    for k, field in enumerate(RESULT):
        if field.ok_only:
            assert keys.index("status") < k, field.key
        if field.kind == "reals" and field.length not in ("parameters", "links"):
            assert RESULT[keys.index(field.length)].kind == "integer" and keys.index(field.length) < k, field.key

def random_result(status: str, links: int) -> dict:
    """A value for every result field (the ok-only ones too: an infeasible result must omit them)."""
    rng = np.random.default_rng(7)
    restarts = 5
    return {"restarts": restarts, "consistent": 3, "restart_costs": np.append(rng.normal(size=restarts - 1), np.inf),
            "restart_violations": rng.uniform(size=restarts) * 1e-7, "status": status, "best_restart": 2,
            "fit_cost": 1.25e-11, "cost": float(rng.normal()), "violation": -3.5e-9,
            "parameters": rng.normal(size=10 * links) * 1e3,
            "residuals": {"gravity": rng.normal(size=2) * 1e-6, "full": rng.normal(size=3)},
            "lambda_min": rng.uniform(size=links)}


def assert_same(got, sent, key):
    if isinstance(sent, dict):
        assert list(got) == list(sent), key
        for kind in sent:
            assert np.array_equal(got[kind], sent[kind]), (key, kind)
    elif isinstance(sent, np.ndarray):
        assert np.array_equal(got, sent), key
    else:
        assert got == sent and type(got) is type(sent), key


@pytest.mark.parametrize("status", ["ok", "infeasible"])
def test_every_result_field_round_trips_through_the_driver(tmp_path, lwr, status):
    result, exe = lwr
    links = result.robot.dof
    sent = random_result(status, links)
    assert set(sent) == {f.key for f in RESULT}
    text = result_text(sent, links)
    (tmp_path / "result.txt").write_text(text)
    subprocess.run([str(exe), "--echo-result", str(tmp_path / "result.txt"), str(tmp_path / "echo.txt")], check=True)
    echoed = (tmp_path / "echo.txt").read_text()
    for got in (read_result_text(echoed), read_result_text(text)):
        for field in RESULT:
            if field.ok_only and status != "ok":
                assert field.key not in got, field.key
            else:
                assert_same(got[field.key], sent[field.key], field.key)
    stage = driver.parse("joint", echoed)  # what the extraction reads of it
    assert (stage.status, stage.restarts, stage.consistent) == (status, sent["restarts"], sent["consistent"])
    assert np.array_equal(stage.restart_costs, sent["restart_costs"])
    assert np.array_equal(stage.restart_violations, sent["restart_violations"])
    assert np.array_equal(stage.p, sent["parameters"])
    if status == "ok":
        assert (stage.fit_cost, stage.cost, stage.violation) == (sent["fit_cost"], sent["cost"], sent["violation"])
        assert_same(stage.residuals, sent["residuals"], "residuals")
        assert np.array_equal(stage.lambda_min, sent["lambda_min"])
    else:
        assert stage.residuals is None and stage.lambda_min is None
