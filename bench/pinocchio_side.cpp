// See pinocchio_side.hpp. Pinocchio is used header-only here: every Pinocchio algorithm is
// instantiated in this file and compiled by the same compiler with the same flags as the
// generated C (PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION is deliberately not defined, so the
// precompiled instantiations in the wheel's libpinocchio_default are not used).
#include "pinocchio_side.hpp"

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/regressor.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <cstdio>
#include <cstring>
#include <string>

struct PinArm {
  pinocchio::Model model;
  pinocchio::Data data;
  int nv;
};

namespace {

bool read_doubles(std::FILE *f, double *x, int count) {
  for (int i = 0; i < count; ++i)
    if (std::fscanf(f, "%lf", &x[i]) != 1) return false;
  return true;
}

}  // namespace

PinArm *pin_load(const char *path, int *nv) {
  std::FILE *f = std::fopen(path, "r");
  if (!f) return nullptr;
  pinocchio::Model model;
  char word[64];
  int njoints = 0;
  bool ok = std::fscanf(f, "%63s %d", word, &njoints) == 2 && std::strcmp(word, "joints") == 0;
  double g[3];
  ok = ok && std::fscanf(f, "%63s", word) == 1 && std::strcmp(word, "gravity") == 0 && read_doubles(f, g, 3);
  for (int j = 0; ok && j < njoints; ++j) {
    // joint <parent> <RZ|PZ>  R[9 row-major] t[3]  mass lever[3] I[9 row-major, about the CoM]
    int parent = 0;
    char type[8];
    double R[9], t[3], m, c[3], I[9];
    ok = std::fscanf(f, "%63s %d %7s", word, &parent, type) == 3 && std::strcmp(word, "joint") == 0 &&
         read_doubles(f, R, 9) && read_doubles(f, t, 3) && read_doubles(f, &m, 1) && read_doubles(f, c, 3) &&
         read_doubles(f, I, 9);
    if (!ok) break;
    Eigen::Matrix3d rot;
    Eigen::Matrix3d inertia;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) {
        rot(r, k) = R[3 * r + k];
        inertia(r, k) = I[3 * r + k];
      }
    const pinocchio::SE3 placement(rot, Eigen::Vector3d(t[0], t[1], t[2]));
    const std::string name = "joint" + std::to_string(j + 1);
    pinocchio::JointIndex id;
    if (std::strcmp(type, "RZ") == 0)
      id = model.addJoint(parent, pinocchio::JointModelRZ(), placement, name);
    else if (std::strcmp(type, "PZ") == 0)
      id = model.addJoint(parent, pinocchio::JointModelPZ(), placement, name);
    else {
      ok = false;
      break;
    }
    model.appendBodyToJoint(id, pinocchio::Inertia(m, Eigen::Vector3d(c[0], c[1], c[2]), inertia),
                            pinocchio::SE3::Identity());
  }
  std::fclose(f);
  if (!ok) return nullptr;
  model.gravity.linear(Eigen::Vector3d(g[0], g[1], g[2]));
  PinArm *arm = new PinArm{model, pinocchio::Data(model), static_cast<int>(model.nv)};
  *nv = arm->nv;
  return arm;
}

void pin_free(PinArm *arm) { delete arm; }

const double *pin_rnea(PinArm *arm, const double *q, const double *qd, const double *qdd) {
  const int n = arm->nv;
  Eigen::Map<const Eigen::VectorXd> qm(q, n), vm(qd, n), am(qdd, n);
  return pinocchio::rnea(arm->model, arm->data, qm, vm, am).data();
}

const double *pin_gravity(PinArm *arm, const double *q) {
  Eigen::Map<const Eigen::VectorXd> qm(q, arm->nv);
  return pinocchio::computeGeneralizedGravity(arm->model, arm->data, qm).data();
}

const double *pin_crba(PinArm *arm, const double *q) {
  Eigen::Map<const Eigen::VectorXd> qm(q, arm->nv);
  return pinocchio::crba(arm->model, arm->data, qm).data();
}

const double *pin_regressor(PinArm *arm, const double *q, const double *qd, const double *qdd) {
  const int n = arm->nv;
  Eigen::Map<const Eigen::VectorXd> qm(q, n), vm(qd, n), am(qdd, n);
  return pinocchio::computeJointTorqueRegressor(arm->model, arm->data, qm, vm, am).data();
}

void pin_parameters(const PinArm *arm, double *out) {
  for (int j = 1; j < arm->model.njoints; ++j) {
    const Eigen::Matrix<double, 10, 1> v = arm->model.inertias[j].toDynamicParameters();
    for (int k = 0; k < 10; ++k) out[10 * (j - 1) + k] = v[k];
  }
}
