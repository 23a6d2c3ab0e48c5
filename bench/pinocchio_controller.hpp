// The Pinocchio side of bench_controller.py: the algorithms a controller, an observer or an
// MPC calls, behind a plain interface (compiled once and cached, like pinocchio_side.cpp).
// The model file is bench_dynamics.py's (write_model); pin_load is pinocchio_side.cpp's.
#pragma once

#include "pinocchio_side.hpp"

// pinocchio::computeCoriolisMatrix; returns data.C, column-major nv x nv.
const double *pin_coriolis(PinArm *arm, const double *q, const double *qd);
// pinocchio::aba; returns data.ddq.
const double *pin_aba(PinArm *arm, const double *q, const double *qd, const double *tau);
// pinocchio::computeRNEADerivatives; dq, dv: data.dtau_dq, data.dtau_dv (row-major: Data's RowMatrixXs).
void pin_rnea_derivatives(PinArm *arm, const double *q, const double *qd, const double *qdd, const double **dq,
                          const double **dv);
// pinocchio::computeABADerivatives; dq, dv: data.ddq_dq, data.ddq_dv (row-major: Data's RowMatrixXs).
void pin_aba_derivatives(PinArm *arm, const double *q, const double *qd, const double *tau, const double **dq,
                         const double **dv);
