"""Where the positions' noise is not the white noise the automatic cutoff was chosen for, the
model's torques pass through the recording's filter like the measured torque they are compared
with (data/automatic.py coloured, Signals.model_filtered; diagnosis/roles.py, moments.py).

A polling logger's late and repeated rows, made a regular grid, put a cutoff of about 4 Hz on
the 1 kHz `viscous` case (tests/simulation/withheld_cases.py: 0.5 Nm s/rad on joints 1 and 6),
and noise between twice the cutoff and the upper band 2.5-5 x the white sigma measured in that
band (1.0-1.2 x on clean 20-bit and 17-bit logs and on the withheld sample). That noise,
differentiated twice, sits in the accelerations up to the cutoff and beyond it once the model's
torque is formed of them; the filtered torque has nothing there. Unfiltered, the nominal model
left 1.34 x the perfect model's residual on joint 2 (which has no effect), and the diagnosis,
with exactly the right values, 1.50 x on joint 1 of the test data. The clean log's model torque
is filtered once (filtering it again would smooth Table V's steps twice).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from simulation import log_variants
from simulation.mujoco_measurements import Encoder
from simulation.perfect import perfect_residual
from simulation.withheld_cases import CASES, nominal_model, simulated_parameters, write_cases
from simulation.withheld_run import run

from dyngen.catalogue import STANDARD_FROM_DYNAMIC
from dyngen.data import condition, read_recording
from dyngen.description import load_robot
from dyngen.diagnosis import roles
from dyngen.runtime import load

CASE = next(c for c in CASES if c.name == "viscous")


@pytest.fixture(scope="module")
def polled(tmp_path_factory):
    base = tmp_path_factory.mktemp("alike")
    doc = write_cases(base / "clean", rate_hz=1000.0, cases=[CASE], encoder=Encoder())
    return log_variants.variant(base / "clean", "polled", base / "polled"), doc, base / "clean"


def test_the_nominal_residual_is_the_perfect_models_where_nothing_was_withheld(polled):
    folder, doc, clean = polled
    robot, model = load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr")
    sig = condition(read_recording(folder / doc["cases"][0]["fit"], robot.dof))
    assert sig.cutoff < 6.0 and sig.model_filtered  # the polled log's noise is not white
    assert condition(read_recording(folder / doc["cases"][0]["holdout"], robot.dof)).model_filtered
    assert not any(condition(read_recording(clean / doc["cases"][0][k], robot.dof)).model_filtered
                   for k in ("fit", "holdout"))  # the clean log's is
    p = nominal_model(robot)
    s = model(STANDARD_FROM_DYNAMIC.name, p)
    segment = roles.segments(model, s, [sig], None, None, 5.0)[0][0]
    inner = sig.inner()
    rms = lambda r: np.sqrt(np.mean(r[inner] ** 2, axis=0))  # noqa: E731
    perfect = rms(perfect_residual(robot, simulated_parameters(CASE, p, doc["seed"]), CASE.effects, sig))
    plain = [j for j in range(robot.dof) if j + 1 not in CASE.effects.viscous]
    assert np.all(rms(segment.residual)[plain] <= 1.02 * perfect[plain]), (rms(segment.residual), perfect)


def test_the_polled_log_predicts_the_test_data_as_the_perfect_model(polled):
    folder, doc, _ = polled
    r = run(load_robot(ROOT / "examples" / "lwr.yaml"), load(ROOT / "generated" / "lwr"), folder, doc, CASE.name,
            "backward")
    assert r["problems"] == [], "\n".join(r["problems"])
    assert r["ratio"] < 1.1, (r["after"], r["perfect"])
