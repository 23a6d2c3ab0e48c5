// Timing harness of bench_kinematics.py: one arm's generated kinematics and control functions
// against Pinocchio (pinocchio_kinematics.cpp) on the same model and random states.
// "arm.inc" (written by bench_kinematics.py) includes the arm's header and defines ARM(fn),
// ARM_N, ARM_P (nominal dynamic parameters) and ARM_QLO / ARM_QHI (joint ranges).
//
// It also defines casb_<fn> for the five kinematics functions: CasADi's C of the same arm
// (bench/casadi_side.py, kinematics_functions), the third side.
//
//   kinematics_harness verify MODEL STATES                 VERIFY <function> <dyngen error> [<CasADi error>]
//   kinematics_harness time MODEL STATES BATCHES WARMUP    TIME <function> <dyngen ns> <pinocchio ns> [<CasADi ns>]
//   kinematics_harness count MODEL STATES FUNCTION SIDE CALLS   (SIDE dyngen | pinocchio | casadi; CALLS = 0: baseline)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "pinocchio_kinematics.hpp"

extern "C" {
#include "arm.inc"
}

namespace {

volatile double g_sink;
const int n = ARM_N;
enum Fn { LINK_POSES, FLANGE_POSE, JACOBIAN, LINK_JACOBIANS, JDOT_QD, CONTROL, CONTROL_J, N_FN };
const char *const kNames[N_FN] = {"link_poses", "flange_pose", "jacobian", "link_jacobians",
                                  "jacobian_dot_qd", "control", "control_with_jacobian"};
const int kLength[N_FN] = {16 * n, 16, 6 * n, 6 * n * n, 6, n * n + 2 * n, n * n + 8 * n + 6};
const int kLongest = *std::max_element(kLength, kLength + N_FN);

struct States {
  std::vector<double> q, qd;
  int count;
  const double *Q(int k) const { return q.data() + (size_t)k * n; }
  const double *QD(int k) const { return qd.data() + (size_t)k * n; }
};

States make_states(int count) {
  States S{std::vector<double>((size_t)n * count), std::vector<double>((size_t)n * count), count};
  std::mt19937_64 rng(20261202u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < count; ++k)
    for (int i = 0; i < n; ++i) {
      S.q[(size_t)k * n + i] = ARM_QLO[i] + (ARM_QHI[i] - ARM_QLO[i]) * unit(rng);
      S.qd[(size_t)k * n + i] = -2.0 + 4.0 * unit(rng);
    }
  return S;
}

double s_params[10 * n];

// The generated function; returns one entry of its output (the sink).
double dyngen(int fn, const double *q, const double *qd, double *out) {
  switch (fn) {
    case LINK_POSES: ARM(link_poses)(q, out); return out[16 * n - 13];
    case FLANGE_POSE: ARM(flange_pose)(q, out); return out[3];
    case JACOBIAN: ARM(jacobian)(q, out); return out[0];
    case LINK_JACOBIANS: ARM(link_jacobians)(q, out); return out[6 * n * n - 1];
    case JDOT_QD: ARM(jacobian_dot_qd)(q, qd, out); return out[0];
    case CONTROL: ARM(control)(q, qd, s_params, out, out + n, out + n + n * n); return out[0] + out[2 * n - 1] + out[n + n * n];
    case CONTROL_J:
      ARM(control_with_jacobian)(q, qd, s_params, out, out + n, out + n + n * n, out + 2 * n + n * n, out + 8 * n + n * n);
      return out[0] + out[2 * n - 1] + out[n + n * n] + out[2 * n + n * n] + out[8 * n + n * n];
  }
  return 0.0;
}

const int N_CASADI = CONTROL;  // the kinematics functions have a CasADi side

double casadi(int fn, const double *q, const double *qd, double *out) {
  switch (fn) {
    case LINK_POSES: casb_link_poses(q, out); return out[16 * n - 13];
    case FLANGE_POSE: casb_flange_pose(q, out); return out[3];
    case JACOBIAN: casb_jacobian(q, out); return out[0];
    case LINK_JACOBIANS: casb_link_jacobians(q, out); return out[6 * n * n - 1];
    case JDOT_QD: casb_jacobian_dot_qd(q, qd, out); return out[0];
  }
  return 0.0;
}

double pinocchio(PkArm *a, int fn, const double *q, const double *qd, double *out) {
  switch (fn) {
    case LINK_POSES: return pk_link_poses(a, q, out);
    case FLANGE_POSE: return pk_flange_pose(a, q, out);
    case JACOBIAN: return pk_jacobian(a, q, out);
    case LINK_JACOBIANS: return pk_link_jacobians(a, q, out);
    case JDOT_QD: return pk_jacobian_dot_qd(a, q, qd, out);
    case CONTROL: return pk_control(a, q, qd, out);
    case CONTROL_J: return pk_control_with_jacobian(a, q, qd, out);
  }
  return 0.0;
}

double relative(const std::vector<double> &mine, const std::vector<double> &theirs, int length) {
  double diff = 0.0, scale = 1.0;
  for (int i = 0; i < length; ++i) {
    diff = std::max(diff, std::fabs(mine[i] - theirs[i]));
    scale = std::max(scale, std::fabs(theirs[i]));
  }
  return diff / scale;
}

// Agreement on every state: max |dyngen - pinocchio| / max(1, max |pinocchio|) per function (CasADi's too).
bool verify(PkArm *a, const States &S) {
  std::vector<double> mine(kLongest), theirs(kLongest), cas(kLongest);
  bool ok = true;
  for (int fn = 0; fn < N_FN; ++fn) {
    double worst = 0.0, worst_cas = 0.0;
    for (int k = 0; k < S.count; ++k) {
      dyngen(fn, S.Q(k), S.QD(k), mine.data());
      pinocchio(a, fn, S.Q(k), S.QD(k), theirs.data());
      worst = std::max(worst, relative(mine, theirs, kLength[fn]));
      if (fn < N_CASADI) {
        casadi(fn, S.Q(k), S.QD(k), cas.data());
        worst_cas = std::max(worst_cas, relative(cas, theirs, kLength[fn]));
      }
    }
    if (fn < N_CASADI) std::printf("VERIFY %s %.3g %.3g\n", kNames[fn], worst, worst_cas);
    else std::printf("VERIFY %s %.3g\n", kNames[fn], worst);
    ok = ok && worst < 1e-9 && worst_cas < 1e-9;
  }
  return ok;
}

template <class F>
double batch_ns(const States &S, F call) {
  const auto start = std::chrono::steady_clock::now();
  double sink = 0.0;
  for (int k = 0; k < S.count; ++k) sink += call(k);
  const auto stop = std::chrono::steady_clock::now();
  g_sink = sink;
  return std::chrono::duration<double, std::nano>(stop - start).count() / S.count;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int fn_from_name(const char *name) {
  for (int f = 0; f < N_FN; ++f)
    if (std::strcmp(name, kNames[f]) == 0) return f;
  return -1;
}

}  // namespace

int main(int argc, char **argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s verify|time|count MODEL STATES ...\n", argv[0]);
    return 2;
  }
  int nv = 0;
  PkArm *arm = pk_load(argv[2], &nv);
  if (!arm || nv != n) {
    std::fprintf(stderr, "cannot load %s\n", argv[2]);
    return 2;
  }
  ARM(standard_from_dynamic)(ARM_P, s_params);
  const States S = make_states(std::atoi(argv[3]));
  std::vector<double> out(kLongest);
  const std::string mode = argv[1];
  if (mode == "verify") return verify(arm, S) ? 0 : 1;
  if (mode == "time" && argc == 6) {
    if (!verify(arm, S)) return 1;
    const int batches = std::atoi(argv[4]), warmup = std::atoi(argv[5]);
    for (int fn = 0; fn < N_FN; ++fn) {
      std::vector<double> mine, theirs, cas;
      for (int b = 0; b < warmup + batches; ++b) {  // interleaved: every side sees the same machine state
        const double d = batch_ns(S, [&](int k) { return dyngen(fn, S.Q(k), S.QD(k), out.data()); });
        const double p = batch_ns(S, [&](int k) { return pinocchio(arm, fn, S.Q(k), S.QD(k), nullptr); });
        const double c = fn < N_CASADI ? batch_ns(S, [&](int k) { return casadi(fn, S.Q(k), S.QD(k), out.data()); }) : 0.0;
        if (b >= warmup) mine.push_back(d), theirs.push_back(p), cas.push_back(c);
      }
      if (fn < N_CASADI) std::printf("TIME %s %.2f %.2f %.2f\n", kNames[fn], median(mine), median(theirs), median(cas));
      else std::printf("TIME %s %.2f %.2f\n", kNames[fn], median(mine), median(theirs));
    }
    return 0;
  }
  if (mode == "count" && argc == 7) {
    const int fn = fn_from_name(argv[4]);
    const bool mine = std::strcmp(argv[5], "dyngen") == 0, cas = std::strcmp(argv[5], "casadi") == 0;
    const long calls = std::atol(argv[6]);
    if (fn < 0 || (cas && fn >= N_CASADI)) return 2;
    double sink = 0.0;
    for (long c = 0; c < calls; ++c) {
      const int k = (int)(c % S.count);
      sink += mine  ? dyngen(fn, S.Q(k), S.QD(k), out.data())
              : cas ? casadi(fn, S.Q(k), S.QD(k), out.data())
                    : pinocchio(arm, fn, S.Q(k), S.QD(k), nullptr);
    }
    g_sink = sink;
    return 0;
  }
  std::fprintf(stderr, "bad arguments\n");
  return 2;
}
