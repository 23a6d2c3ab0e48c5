"""MuJoCo data generators: simulated "measured" recordings of the LWR with effects the nominal
model leaves out (the benchmark's and the tests' data), and the verdict on what a diagnosis
makes of them, which the benchmark and the tests share.

    mujoco_measurements.py  the arm in MuJoCo, effects, noise, encoders; recordings as CSV
    mujoco_tracking.py      forward simulation under a computed-torque controller
    withheld_cases.py       the withheld-effect cases and their case folder (truth.json)
    perfect.py              what the simulated arm with exactly the injected laws leaves
    withheld_verdict.py     does a diagnosis match a case's truth (the list of mismatches)
    withheld_run.py         one case through the diagnosis as a user runs it, and its verdict

Test support, owned by the tests (tests/ is on their sys.path: conftest.py); the bench scripts
import it too (bench/common.py on_path).
"""
