// The Pinocchio side of bench_kinematics.py (pinocchio_kinematics.cpp), behind a plain
// interface: compiled once, every call out of line like the generated functions.
#pragma once

struct PkArm;

PkArm *pk_load(const char *path, int *nv);  // nullptr on error
void pk_free(PkArm *arm);
// Each returns one number of its result (for the timing sink); out (or nullptr) receives the
// result in the generated function's layout.
double pk_link_poses(PkArm *arm, const double *q, double *out);
double pk_flange_pose(PkArm *arm, const double *q, double *out);
double pk_jacobian(PkArm *arm, const double *q, double *out);
double pk_link_jacobians(PkArm *arm, const double *q, double *out);
double pk_jacobian_dot_qd(PkArm *arm, const double *q, const double *qd, double *out);
double pk_control(PkArm *arm, const double *q, const double *qd, double *out);
double pk_control_with_jacobian(PkArm *arm, const double *q, const double *qd, double *out);
