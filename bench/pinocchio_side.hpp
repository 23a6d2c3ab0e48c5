// The Pinocchio side of bench_dynamics.py, behind a plain interface so that it is compiled
// once (its translation unit takes a minute) and cached: the model is read at run time from
// the text file written by bench_dynamics.py, so this code does not depend on the arm.
//
// Every function is an ordinary out-of-line call from the timing loop, exactly like the
// generated <name>_rnea etc. (separate translation units, no LTO on either side).
#pragma once

struct PinArm;

// Reads a model file (format: see write_model() in bench_dynamics.py); nullptr on error.
PinArm *pin_load(const char *path, int *nv);
void pin_free(PinArm *arm);

// pinocchio::rnea; returns data.tau (nv entries).
const double *pin_rnea(PinArm *arm, const double *q, const double *qd, const double *qdd);
// pinocchio::computeGeneralizedGravity; returns data.g (nv entries).
const double *pin_gravity(PinArm *arm, const double *q);
// pinocchio::crba (default convention); returns data.M, column-major nv x nv, of which
// crba fills only the upper triangle (M(i, j), i <= j, at [i + j * nv]).
const double *pin_crba(PinArm *arm, const double *q);
// pinocchio::computeJointTorqueRegressor; returns data.jointTorqueRegressor, column-major
// nv x 10 nv, its columns Pinocchio's dynamic parameters per body (see pin_parameters).
const double *pin_regressor(PinArm *arm, const double *q, const double *qd, const double *qdd);
// Pinocchio's dynamic parameters (10 nv): per body inertia.toDynamicParameters(), the
// vector its regressor multiplies.
void pin_parameters(const PinArm *arm, double *out);
