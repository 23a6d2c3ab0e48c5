// See pinocchio_controller.hpp. Header-only Pinocchio, the same compiler and flags as the C.
#include "pinocchio_controller.hpp"

#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>

struct PinArm {  // as in pinocchio_side.cpp (same layout: the object is created there)
  pinocchio::Model model;
  pinocchio::Data data;
  int nv;
};

namespace {
using Vec = Eigen::Map<const Eigen::VectorXd>;
}

const double *pin_coriolis(PinArm *arm, const double *q, const double *qd) {
  const int n = arm->nv;
  return pinocchio::computeCoriolisMatrix(arm->model, arm->data, Vec(q, n), Vec(qd, n)).data();
}

const double *pin_aba(PinArm *arm, const double *q, const double *qd, const double *tau) {
  const int n = arm->nv;
  return pinocchio::aba(arm->model, arm->data, Vec(q, n), Vec(qd, n), Vec(tau, n)).data();
}

void pin_rnea_derivatives(PinArm *arm, const double *q, const double *qd, const double *qdd, const double **dq,
                          const double **dv) {
  const int n = arm->nv;
  pinocchio::computeRNEADerivatives(arm->model, arm->data, Vec(q, n), Vec(qd, n), Vec(qdd, n));
  *dq = arm->data.dtau_dq.data();
  *dv = arm->data.dtau_dv.data();
}

void pin_aba_derivatives(PinArm *arm, const double *q, const double *qd, const double *tau, const double **dq,
                         const double **dv) {
  const int n = arm->nv;
  pinocchio::computeABADerivatives(arm->model, arm->data, Vec(q, n), Vec(qd, n), Vec(tau, n));
  *dq = arm->data.ddq_dq.data();
  *dv = arm->data.ddq_dv.data();
}
