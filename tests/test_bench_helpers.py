"""The benchmark suite's pure-Python helpers (bench/): growth-exponent fit, synthetic arms,
peak-memory measurement, BENCHMARKS.md sections. The benchmarks themselves are not tests."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest
import sympy as sp

BENCH = Path(__file__).resolve().parents[1] / "bench"
sys.path.insert(0, str(BENCH))

import run_all  # noqa: E402
from bench_scaling import fit_exponent  # noqa: E402
from peak_memory import run_measured  # noqa: E402
from synthetic_arm import synthetic_arm_yaml  # noqa: E402

from dyngen.description import load_robot  # noqa: E402


def test_fit_exponent_recovers_known_power_laws():
    ns = [6, 7, 9, 12]
    assert fit_exponent(ns, [3.0 * n ** 2.5 for n in ns]) == pytest.approx(2.5, abs=1e-12)
    assert fit_exponent([2, 4], [5.0, 10.0]) == pytest.approx(1.0, abs=1e-12)
    # not a power law: c n^2 + n^3 lies between the two pure laws
    assert 2.0 < fit_exponent(ns, [100 * n ** 2 + n ** 3 for n in ns]) < 3.0
    with pytest.raises(ValueError):
        fit_exponent([4], [1.0])


@pytest.mark.parametrize("n", [2, 4, 7, 12])
def test_synthetic_arms_load_with_the_promised_features(n, tmp_path):
    path = tmp_path / f"synthetic{n}.yaml"
    path.write_text(synthetic_arm_yaml(n))
    robot = load_robot(path)  # dyngen's own loader and validation, not the writer's idea of the file
    assert robot.name == f"synthetic{n}" and robot.dof == n and robot.convention == "standard"
    assert [j.type for j in robot.joints].count("prismatic") == 1
    assert all(j.a != 0 and j.d != 0 for j in robot.joints)
    alphas = {j.alpha for j in robot.joints}
    assert {sp.Integer(0), sp.pi / 2}.issubset(alphas)
    if n >= 3:
        assert -sp.pi / 2 in alphas and robot.joints[2].type == "prismatic"
    assert synthetic_arm_yaml(n) == path.read_text()  # deterministic


def test_run_measured_reports_the_childs_peak_memory_and_exit_code():
    big = run_measured([sys.executable, "-c", "x = bytearray(150 * 2**20); x[::4096] = b'1' * len(x[::4096]); "
                        "print('ok')"])
    small = run_measured([sys.executable, "-c", "import sys; print('bye'); sys.exit(3)"])
    assert big.returncode == 0 and big.stdout.strip() == "ok"
    assert small.returncode == 3 and small.stdout.strip() == "bye"
    assert big.max_rss_mib >= 150  # the allocation itself
    assert big.max_rss_mib - small.max_rss_mib == pytest.approx(150, abs=40)  # the same interpreter otherwise


def test_run_measured_does_not_count_the_callers_memory():
    # Linux counts the RSS of the process a child was forked from in the child's maximum;
    # measured straight from this (now > 200 MiB) process, `true` would report > 200 MiB.
    ballast = bytearray(200 * 2**20)
    ballast[::4096] = b"1" * len(ballast[::4096])
    tiny = run_measured(["true"])
    assert tiny.returncode == 0
    assert tiny.max_rss_mib < 50
    assert 0 < tiny.floor_kib < 50 * 1024
    del ballast


def test_section_body_demotes_headings_and_points_images_at_the_results(tmp_path, monkeypatch):
    monkeypatch.setattr(run_all, "RESULTS", tmp_path)
    (tmp_path / "scaling.md").write_text("# Title\n\ntext\n\n## Sub\n\n![plot](scaling.png)\n![web](https://x/y.png)\n")
    body = run_all.section_body("scaling")
    assert body.splitlines() == ["text", "", "### Sub", "",
                                 "![plot](bench/results/scaling.png)", "![web](https://x/y.png)"]
    assert run_all.section_body("missing") is None
