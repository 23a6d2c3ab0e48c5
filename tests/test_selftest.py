"""The generated self-test: its embedded values against the Lagrangian oracle, and the CMake
build (static library + self-test + ctest) of generated/lwr and of other arms.

The embedded values come from the generator's own evaluation of its symbolic programs; the
oracle here is the independent numpy Lagrangian (tests/oracles/lagrangian.py).
"""

from __future__ import annotations

import json
import shutil
import subprocess

import numpy as np
import pytest
from conftest import ROOT
from oracles import lagrangian as lag
from oracles.arm import Arm

from dyngen import catalogue
from dyngen.atomic import write_folder
from dyngen.description import load_robot
from dyngen.generate import build, generate

LWR_FOLDER = ROOT / "generated" / "lwr"


def selftest_checks(states: int = 3) -> int:
    """One check per output of a catalogue function of p alone, one per output and state for the others."""
    return sum((states if f.state else 1) * len(f.outputs) for f in catalogue.FUNCTIONS)


def normwise(got, want) -> float:
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    return float(np.max(np.abs(got - want)) / max(1.0, float(np.max(np.abs(want)))))


def check_embedded_values(manifest, arm):
    check = manifest["selftest"]
    p = np.array(check["p"])
    assert len(check["states"]) >= 3
    for state in check["states"]:
        q, qd, qdd = (np.array(state[k]) for k in ("q", "qd", "qdd"))
        assert normwise(state["tau"], lag.inverse_dynamics(arm, q, qd, qdd, p)) < 1e-9
        assert normwise(state["g"], lag.gravity(arm, q, p)) < 1e-9
        assert normwise(np.reshape(state["M"], (len(q), len(q))), lag.mass_matrix(arm, q, p)) < 1e-9


def test_embedded_values_match_the_lagrangian(built):
    check_embedded_values(built.emitted.manifest, built.arm)
    if built.robot.nominal:  # the self-test runs the YAML's own parameters when it has them
        assert np.allclose(built.emitted.manifest["selftest"]["p"], built.nominal, rtol=0, atol=0)


def test_embedded_values_with_symbolic_gravity(tmp_path):
    yaml = tmp_path / "lwr.yaml"
    yaml.write_text((ROOT / "examples" / "lwr.yaml").read_text().replace("gravity: [0, 0, -9.81]",
                                                                        "gravity: [gx, gy, gz]"))
    _, emitted = build(load_robot(yaml))
    assert emitted.manifest["selftest"]["gravity_symbols"] == [9.81, -2.5, 1.25]  # gx, gy, gz in the self-test
    check_embedded_values(emitted.manifest, Arm.from_yaml(yaml, {"gx": 9.81, "gy": -2.5, "gz": 1.25}))
    write_folder(tmp_path / "lwr", emitted.files)
    result = run_selftest_with_cc(tmp_path / "lwr", tmp_path / "bin")
    assert result.returncode == 0 and "PASS" in result.stdout, result.stdout


def cmake_build_and_ctest(folder, build_dir, *options) -> str:
    """Configure, build and ctest; returns the self-test's verdict line (from ctest -V)."""
    subprocess.run(["cmake", "-S", str(folder), "-B", str(build_dir), *options], check=True, capture_output=True)
    subprocess.run(["cmake", "--build", str(build_dir)], check=True, capture_output=True)
    assert (build_dir / f"lib{json.loads((folder / 'manifest.json').read_text())['robot']}_dynamics.a").exists()
    result = subprocess.run(["ctest", "-V"], cwd=build_dir, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "100% tests passed" in result.stdout
    return next(line for line in result.stdout.splitlines() if "self-test (" in line)


def test_cmake_builds_generated_lwr_and_its_selftest_passes(tmp_path):
    double = cmake_build_and_ctest(LWR_FOLDER, tmp_path / "double")
    assert f"lwr self-test (double): PASS, {selftest_checks()} checks at 3 states" in double
    single = cmake_build_and_ctest(LWR_FOLDER, tmp_path / "float", "-DLWR_USE_FLOAT=ON")
    assert "lwr self-test (float): PASS" in single


def test_cmake_selftest_of_a_freshly_generated_arm(tmp_path):
    generated = generate(ROOT / "examples" / "stanford.yaml", tmp_path / "generated")  # prismatic joint
    line = cmake_build_and_ctest(generated.folder, tmp_path / "build")
    assert "stanford self-test (double): PASS" in line


def test_as_a_subdirectory_only_the_library_is_built(tmp_path):
    """A firmware project add_subdirectory()s the folder: no self-test executable by default."""
    shutil.copytree(LWR_FOLDER, tmp_path / "src" / "lwr")
    (tmp_path / "src" / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.13)\nproject(firmware C)\nadd_subdirectory(lwr)\n")
    subprocess.run(["cmake", "-S", str(tmp_path / "src"), "-B", str(tmp_path / "b")], check=True, capture_output=True)
    targets = subprocess.run(["cmake", "--build", str(tmp_path / "b"), "--target", "help"], capture_output=True,
                             text=True, check=True).stdout
    assert "lwr_dynamics" in targets and "lwr_selftest" not in targets


def run_selftest_with_cc(folder, build_dir, *flags):
    build_dir.mkdir(parents=True, exist_ok=True)
    exe = build_dir / "selftest"
    sources = sorted(str(p) for p in folder.glob("*.c"))  # the library's and the self-test's
    subprocess.run(["cc", "-std=c99", "-O1", *flags, "-I", str(folder), *sources, "-o", str(exe), "-lm"], check=True,
                   capture_output=True)
    return subprocess.run([str(exe)], capture_output=True, text=True)


@pytest.mark.parametrize("flags", [(), ("-DLWR_USE_FLOAT",)], ids=["double", "float"])
def test_selftest_fails_on_a_wrong_model(tmp_path, flags):
    """The self-test can fail: a gravity constant off by 0.1% in the dynamics is caught."""
    folder = tmp_path / "lwr"
    shutil.copytree(LWR_FOLDER, folder)
    dynamics = folder / "lwr_dynamics.c"
    text = dynamics.read_text()
    assert "LWR_K(9.81)" in text
    dynamics.write_text(text.replace("LWR_K(9.81)", "LWR_K(9.82)"))
    result = run_selftest_with_cc(folder, tmp_path / "bin", *flags)
    assert result.returncode == 1
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 1 and "FAIL" in lines[0], result.stdout
