#!/usr/bin/env bash
# The real-arm example: three KUKA LWR4+ runs (FloBaRoID, LGPL-3.0; see README.md).
# 1. identify the full base coefficients on measurement 1 (least squares, eq. 11), then physically
#    consistent link parameters with friction, offsets, rotor inertia, ripple and base tilt;
# 2. diagnose the paper's parameters: fit effects on measurement 1 (selection on blocks of it),
#    test on measurement 3 (a different, faster trajectory), write report, JSON, figures, effects.
set -euo pipefail
cd "$(dirname "$0")/../.."
HERE=examples/lwr4-real
python3 -m dyngen identify examples/lwr.yaml --ols --data $HERE/measurement_1.csv -o $HERE/results/identified_full.yaml
# physically consistent identification with friction (prior: the paper's parameters), URDF and MJCF
python3 -m dyngen identify examples/lwr.yaml --data $HERE/measurement_1.csv --prior examples/lwr_paper_solution.yaml \
    --friction coulomb,viscous,offset,armature,ripple --tilt -o $HERE/results/consistent/identified.yaml
python3 -m dyngen diagnose examples/lwr.yaml --params examples/lwr_paper_solution.yaml \
    --data $HERE/measurement_1.csv --test $HERE/measurement_3.csv --out $HERE/results
