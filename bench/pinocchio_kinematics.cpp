// The Pinocchio side of bench_kinematics.py, one translation unit compiled once and cached
// (header-only Pinocchio, the same compiler and flags as the generated C). The model file is
// bench_dynamics.py's format followed by one line per operational frame:
//   frame <joint> R[9 row-major] t[3]      (the link frames 1..N, then the tool)
// Each pk_* function is what a careful Pinocchio user calls for the generated function of the
// same name; with out == nullptr nothing is copied (timing), else the result is written in
// the generated function's layout (row-major) for the agreement check.
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "pinocchio_kinematics.hpp"

struct PkArm {
  pinocchio::Model model;
  pinocchio::Data data;
  std::vector<pinocchio::FrameIndex> frames;  // link frames 1..N, then the tool
  pinocchio::Data::Matrix6x J;
  int nv;
};

namespace {

bool read_doubles(std::FILE *f, double *x, int count) {
  for (int i = 0; i < count; ++i)
    if (std::fscanf(f, "%lf", &x[i]) != 1) return false;
  return true;
}

Eigen::Matrix3d matrix3(const double *R) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) m(r, k) = R[3 * r + k];
  return m;
}

void write_pose(const pinocchio::SE3 &T, double *out) {
  const Eigen::Matrix4d H = T.toHomogeneousMatrix();
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k) out[4 * r + k] = H(r, k);
}

void write_rows(const pinocchio::Data::Matrix6x &J, double *out) {
  for (int r = 0; r < 6; ++r)
    for (int k = 0; k < J.cols(); ++k) out[r * J.cols() + k] = J(r, k);
}

const pinocchio::ReferenceFrame kWorld = pinocchio::LOCAL_WORLD_ALIGNED;

}  // namespace

PkArm *pk_load(const char *path, int *nv) {
  std::FILE *f = std::fopen(path, "r");
  if (!f) return nullptr;
  pinocchio::Model model;
  char word[64];
  int njoints = 0;
  double g[3];
  bool ok = std::fscanf(f, "%63s %d", word, &njoints) == 2 && std::strcmp(word, "joints") == 0;
  ok = ok && std::fscanf(f, "%63s", word) == 1 && std::strcmp(word, "gravity") == 0 && read_doubles(f, g, 3);
  for (int j = 0; ok && j < njoints; ++j) {
    int parent = 0;
    char type[8];
    double R[9], t[3], m, c[3], I[9];
    ok = std::fscanf(f, "%63s %d %7s", word, &parent, type) == 3 && std::strcmp(word, "joint") == 0 &&
         read_doubles(f, R, 9) && read_doubles(f, t, 3) && read_doubles(f, &m, 1) && read_doubles(f, c, 3) &&
         read_doubles(f, I, 9);
    if (!ok) break;
    const pinocchio::SE3 placement(matrix3(R), Eigen::Vector3d(t[0], t[1], t[2]));
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
    model.appendBodyToJoint(id, pinocchio::Inertia(m, Eigen::Vector3d(c[0], c[1], c[2]), matrix3(I)),
                            pinocchio::SE3::Identity());
  }
  std::vector<pinocchio::FrameIndex> frames;
  for (int k = 0; ok && k <= njoints; ++k) {
    int joint = 0;
    double R[9], t[3];
    ok = std::fscanf(f, "%63s %d", word, &joint) == 2 && std::strcmp(word, "frame") == 0 && read_doubles(f, R, 9) &&
         read_doubles(f, t, 3);
    if (!ok) break;
    const std::string name = k < njoints ? "frame" + std::to_string(k + 1) : std::string("tool");
    frames.push_back(model.addFrame(pinocchio::Frame(name, joint, pinocchio::SE3(matrix3(R), Eigen::Vector3d(t[0], t[1], t[2])),
                                                     pinocchio::OP_FRAME)));
  }
  std::fclose(f);
  if (!ok) return nullptr;
  model.gravity.linear(Eigen::Vector3d(g[0], g[1], g[2]));
  PkArm *arm = new PkArm{model, pinocchio::Data(model), frames, pinocchio::Data::Matrix6x::Zero(6, model.nv),
                         static_cast<int>(model.nv)};
  *nv = arm->nv;
  return arm;
}

void pk_free(PkArm *arm) { delete arm; }

// framesForwardKinematics: every joint and frame placement.
double pk_link_poses(PkArm *a, const double *q, double *out) {
  pinocchio::framesForwardKinematics(a->model, a->data, Eigen::Map<const Eigen::VectorXd>(q, a->nv));
  if (out)
    for (int i = 0; i < a->nv; ++i) write_pose(a->data.oMf[a->frames[i]], out + 16 * i);
  return a->data.oMf[a->frames[a->nv - 1]].translation()[0];
}

// forwardKinematics, then the one frame.
double pk_flange_pose(PkArm *a, const double *q, double *out) {
  pinocchio::forwardKinematics(a->model, a->data, Eigen::Map<const Eigen::VectorXd>(q, a->nv));
  const pinocchio::SE3 &T = pinocchio::updateFramePlacement(a->model, a->data, a->frames.back());
  if (out) write_pose(T, out);
  return T.translation()[0];
}

// computeFrameJacobian: forward kinematics and the frame's Jacobian in one call.
double pk_jacobian(PkArm *a, const double *q, double *out) {
  a->J.setZero();
  pinocchio::computeFrameJacobian(a->model, a->data, Eigen::Map<const Eigen::VectorXd>(q, a->nv), a->frames.back(),
                                  kWorld, a->J);
  if (out) write_rows(a->J, out);
  return a->J(0, 0);
}

// computeJointJacobians, then getFrameJacobian of every link frame.
double pk_link_jacobians(PkArm *a, const double *q, double *out) {
  pinocchio::computeJointJacobians(a->model, a->data, Eigen::Map<const Eigen::VectorXd>(q, a->nv));
  double sink = 0.0;
  for (int i = 0; i < a->nv; ++i) {
    a->J.setZero();
    pinocchio::getFrameJacobian(a->model, a->data, a->frames[i], kWorld, a->J);
    if (out) write_rows(a->J, out + 6 * a->nv * i);
    sink += a->J(0, 0);
  }
  return sink;
}

// forwardKinematics with qdd = 0, then the frame's classical acceleration = Jdot qd.
double pk_jacobian_dot_qd(PkArm *a, const double *q, const double *qd, double *out) {
  const int n = a->nv;
  pinocchio::forwardKinematics(a->model, a->data, Eigen::Map<const Eigen::VectorXd>(q, n),
                               Eigen::Map<const Eigen::VectorXd>(qd, n), Eigen::VectorXd::Zero(n));
  const pinocchio::Motion acc = pinocchio::getFrameClassicalAcceleration(a->model, a->data, a->frames.back(), kWorld);
  if (out)
    for (int k = 0; k < 3; ++k) out[k] = acc.linear()[k], out[3 + k] = acc.angular()[k];
  return acc.linear()[0];
}

// computeGeneralizedGravity, crba and nonLinearEffects (c = nle - g); out: g, M (full), c.
double pk_control(PkArm *a, const double *q, const double *qd, double *out) {
  const int n = a->nv;
  Eigen::Map<const Eigen::VectorXd> qm(q, n), vm(qd, n);
  pinocchio::computeGeneralizedGravity(a->model, a->data, qm);
  pinocchio::crba(a->model, a->data, qm);
  pinocchio::nonLinearEffects(a->model, a->data, qm, vm);
  if (out) {
    for (int i = 0; i < n; ++i) out[i] = a->data.g[i], out[n + n * n + i] = a->data.nle[i] - a->data.g[i];
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) out[n + n * i + j] = i <= j ? a->data.M(i, j) : a->data.M(j, i);
  }
  return a->data.g[0] + a->data.M(0, n - 1) + a->data.nle[0];
}

// pk_control, then the tool's Jacobian and Jdot qd as above; out: g, M, c, J, Jdot qd.
double pk_control_with_jacobian(PkArm *a, const double *q, const double *qd, double *out) {
  const int n = a->nv;
  double sink = pk_control(a, q, qd, out);
  sink += pk_jacobian(a, q, out ? out + 2 * n + n * n : nullptr);
  sink += pk_jacobian_dot_qd(a, q, qd, out ? out + 8 * n + n * n : nullptr);
  return sink;
}
