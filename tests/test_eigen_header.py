"""The Eigen header generated/lwr/lwr.hpp, compiled with g++ against the system Eigen.

tests/cpp/eigen_check.cpp calls every kind of wrapper (fixed-size matrices, Maps over plain
arrays for inputs and outputs, column blocks); its results must equal the C functions called
through cffi and the numpy Lagrangian. Arguments the header must refuse (a strided row, a
float vector in the double build, an expression) must not compile.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest
from cbuild import compile_objects
from conftest import ROOT
from oracles import lagrangian as lag
from oracles.arm import Arm
from oracles.random_params import random_parameters

from dyngen.runtime import load

FOLDER = ROOT / "generated" / "lwr"
EIGEN = "/usr/include/eigen3"
CXX = ["g++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-isystem", EIGEN, "-I", str(FOLDER)]
N_STATES = 20


@pytest.fixture(scope="module")
def check_program(tmp_path_factory) -> Path:
    build = tmp_path_factory.mktemp("eigen")
    objects = [o for o in compile_objects(FOLDER, build) if o.stem != "lwr_selftest"]
    exe = build / "eigen_check"
    subprocess.run([*CXX, "-O1", str(ROOT / "tests" / "cpp" / "eigen_check.cpp"), *map(str, objects), "-o", str(exe),
                    "-lm"], check=True, capture_output=True, text=True)
    return exe


def normwise(got, want) -> float:
    return float(np.max(np.abs(np.asarray(got) - np.asarray(want))) / max(1.0, float(np.max(np.abs(want)))))


def test_wrappers_equal_the_c_functions_and_the_lagrangian(check_program, tmp_path):
    rng = np.random.default_rng(17)
    p = random_parameters(7, seed=rng)
    states = [(rng.uniform(-np.pi, np.pi, 7), rng.uniform(-2, 2, 7), rng.uniform(-5, 5, 7)) for _ in range(N_STATES)]
    text = " ".join(repr(float(v)) for v in p) + "\n"
    text += "\n".join(" ".join(repr(float(v)) for v in np.concatenate(state)) for state in states) + "\n"
    result = subprocess.run([str(check_program)], input=text, capture_output=True, text=True, check=True)
    lines = [line.split() for line in result.stdout.splitlines()]
    outputs: dict[str, list] = {}
    for name, *values in lines:
        outputs.setdefault(name, []).append(np.array([float(v) for v in values]))

    c = load(FOLDER, cache_dir=tmp_path)
    arm = Arm.from_yaml(ROOT / "examples" / "lwr.yaml")
    s = c("standard_from_dynamic", p)
    same = 1e-14  # the same C code: only the compilation (-O1 against -O2) may differ, in the last bits
    assert normwise(outputs["s"][0], s) < same
    for name in ("pi_gravity", "pi_inertia", "pi_full", "pi_full_jacobian"):
        assert normwise(outputs[name][0], c(name, p).ravel()) < same, name
    assert all(len(outputs[name]) == N_STATES for name in ("tau_map", "tau_block", "g", "M", "Y", "Y_pi"))
    for k, (q, qd, qdd) in enumerate(states):
        tau = lag.inverse_dynamics(arm, q, qd, qdd, p)
        for name in ("tau_map", "tau_block", "Y_pi"):
            assert normwise(outputs[name][k], tau) < 1e-9, name
        assert normwise(outputs["tau_map"][k], c("rnea", q, qd, qdd, s)) < same
        assert normwise(outputs["g"][k], lag.gravity(arm, q, p)) < 1e-9
        assert normwise(outputs["M"][k].reshape(7, 7), lag.mass_matrix(arm, q, p)) < 1e-9
        assert normwise(outputs["M"][k], c("mass_matrix", q, s).ravel()) < same  # row-major, as in C
        assert normwise(outputs["Y_gravity"][k], c("regressor_gravity", q).ravel()) < same
        assert normwise(outputs["Y_inertia"][k], c("regressor_inertia", q).ravel()) < same
        assert normwise(outputs["Y"][k], c("regressor", q, qd, qdd).ravel()) < same
        for name in ("flange_pose", "link_poses", "jacobian", "link_jacobians"):
            assert normwise(outputs[name][k], c(name, q).ravel()) < same, name
        assert normwise(outputs["jacobian_dot_qd"][k], c("jacobian_dot_qd", q, qd)) < same
        g, M, cv = (x.ravel() for x in c("control", q, qd, s))
        for name, want in (("control_g", g), ("control_M", M), ("control_c", cv)):
            assert normwise(outputs[name][k], want) < same, name
        assert normwise(outputs["control_g"][k], lag.gravity(arm, q, p)) < 1e-9
        assert normwise(outputs["control_c"][k], lag.coriolis(arm, q, qd, p)) < 1e-9
        assert normwise(outputs["control_J"][k], c("jacobian", q).ravel()) < same
        assert normwise(outputs["control_jdot_qd"][k], c("jacobian_dot_qd", q, qd)) < same


REFUSED = {
    "strided row": "Eigen::Matrix<double, 3, 7> A = Eigen::Matrix<double, 3, 7>::Zero();\n"
                   "lwr::Joints g = lwr::gravity(A.row(0).transpose(), s);",
    "float vector": "Eigen::Matrix<float, 7, 1> q = Eigen::Matrix<float, 7, 1>::Zero();\n"
                    "lwr::Joints g = lwr::gravity(q, s);",
    "expression": "lwr::Joints q = lwr::Joints::Zero();\nlwr::Joints g = lwr::gravity(q + q, s);",
    "wrong size output": "lwr::Joints q = lwr::Joints::Zero();\nEigen::Matrix<double, 6, 1> g;\n"
                         "lwr::gravity(q, s, g);",
}


def test_arguments_that_would_need_a_copy_do_not_compile(tmp_path):
    """One file, one refused call per line; g++ must report the header's message at each of them.
    (The accepted forms, Maps and column blocks, are compiled by the check program above.)"""
    body = "".join(f"{{ // {case}\n{code}\n(void)g;\n}}\n" for case, code in REFUSED.items())
    source = tmp_path / "refused.cpp"
    source.write_text('#include "lwr.hpp"\nint main()\n{\nlwr::Parameters s = lwr::Parameters::Zero();\n'
                      f"{body}return 0;\n}}\n")
    result = subprocess.run([*CXX, "-fsyntax-only", str(source)], capture_output=True, text=True)
    assert result.returncode != 0
    lines = source.read_text().splitlines()
    for case in REFUSED:
        call = next(k for k, line in enumerate(lines, 1) if f"// {case}" in line) + len(REFUSED[case].splitlines())
        assert f"refused.cpp:{call}:" in result.stderr, (case, call, result.stderr[:3000])
    assert result.stderr.count("lwr.hpp: argument must be") + result.stderr.count("lwr.hpp: output must be") \
        >= len(REFUSED)
