// Harness of bench_controller.py: one arm's generated controller functions against Pinocchio's
// and CasADi's (bench/casadi_side.py, parameters as input and baked), in one binary, the same
// compiler and flags. "arm.inc" (written by bench_controller.py) includes the arm's headers and
// defines ARM(fn) (its C names), N, P (nominal dynamic parameters), QLO, QHI and the CasADi
// wrappers cas_<fn>(inputs..., params, out) and casb_<fn>(inputs..., out).
//
//   harness verify    MODEL STATES                     VERIFY <function> <dyngen> <casadi> <casadi baked>
//                                                      (max relative error of each against Pinocchio;
//                                                      normwise for FD and its derivatives: verify_one)
//   harness time      MODEL STATES BATCHES              TIME <function> <dyngen> <pinocchio> <casadi> <casadi baked> (ns)
//   harness callgrind MODEL STATES FUNCTION SIDE CALLS  SIDE: dyngen pinocchio casadi casadi_baked
//                                                      (CALLS = 0: the baseline run)
//
// FUNCTION (dyngen vs Pinocchio):
//   coriolis        ARM(coriolis_matrix)               vs computeCoriolisMatrix
//   mass_matrix_dot ARM(mass_matrix_derivative)        vs computeCoriolisMatrix, then C + C^T
//   slotine_li      ARM(regressor_slotine_li)          vs computeJointTorqueRegressor (Pinocchio has no
//                                                         Slotine-Li regressor: the nearest, for scale)
//   fd              ARM(forward_dynamics)              vs aba
//   rnea_derivatives ARM(rnea_derivatives)             vs computeRNEADerivatives
//   fd_derivatives  ARM(forward_dynamics_derivatives)  vs computeABADerivatives
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "arm.inc"
#include "pinocchio_controller.hpp"

namespace {

volatile double g_sink;
enum Fn { CORIOLIS, MDOT, SLOTINE_LI, FD, RNEA_DERIVATIVES, FD_DERIVATIVES, N_FN };
const char *const kNames[N_FN] = {"coriolis", "mass_matrix_dot", "slotine_li", "fd", "rnea_derivatives",
                                  "fd_derivatives"};

struct Setup {
  PinArm *pin = nullptr;
  double s[10 * N], pi[N_PI_FULL], pin_params[10 * N];
  std::vector<double> q, qd, qdd, tau;
  std::vector<double> out = std::vector<double>(N * std::max(2 * N, 10 * N));
  int count = 0;
  const double *Q(int k) const { return &q[(size_t)k * N]; }
  const double *QD(int k) const { return &qd[(size_t)k * N]; }
  const double *QDD(int k) const { return &qdd[(size_t)k * N]; }
  const double *TAU(int k) const { return &tau[(size_t)k * N]; }
};

bool setup(const char *model, int states, Setup &S) {
  int nv = 0;
  S.pin = pin_load(model, &nv);
  if (!S.pin || nv != N) return false;
  ARM(standard_from_dynamic)(P, S.s);
  ARM(pi_full)(P, S.pi);
  pin_parameters(S.pin, S.pin_params);
  std::mt19937_64 rng(20240611u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  S.count = states;
  for (int k = 0; k < states; ++k)
    for (int i = 0; i < N; ++i) {
      S.q.push_back(QLO[i] + (QHI[i] - QLO[i]) * unit(rng));
      S.qd.push_back(-2.0 + 4.0 * unit(rng));
      S.qdd.push_back(-5.0 + 10.0 * unit(rng));
    }
  S.tau.resize(S.q.size());
  for (int k = 0; k < states; ++k) ARM(rnea)(S.Q(k), S.QD(k), S.QDD(k), S.s, &S.tau[(size_t)k * N]);
  return true;
}

template <int F>
double dyngen_call(Setup &S, int k) {
  double *o = S.out.data();
  if constexpr (F == CORIOLIS) ARM(coriolis_matrix)(S.Q(k), S.QD(k), S.s, o);
  if constexpr (F == MDOT) ARM(mass_matrix_derivative)(S.Q(k), S.QD(k), S.s, o);
  if constexpr (F == SLOTINE_LI) ARM(regressor_slotine_li)(S.Q(k), S.QD(k), S.QD((k + 1) % S.count), S.QDD(k), o);
  if constexpr (F == FD) ARM(forward_dynamics)(S.Q(k), S.QD(k), S.TAU(k), S.s, o);
  if constexpr (F == RNEA_DERIVATIVES) ARM(rnea_derivatives)(S.Q(k), S.QD(k), S.QDD(k), S.s, o);
  if constexpr (F == FD_DERIVATIVES) ARM(forward_dynamics_derivatives)(S.Q(k), S.QD(k), S.TAU(k), S.s, o);
  return o[0] + o[N - 1];
}

// CasADi: D and Y row-major as dyngen's; casb_slotine_li is cas_slotine_li (Y holds no parameters).
template <int F, bool Baked>
double casadi_call(Setup &S, int k) {
  double *o = S.out.data();
  const double *p = S.pin_params;
  if constexpr (F == CORIOLIS) Baked ? casb_coriolis(S.Q(k), S.QD(k), o) : cas_coriolis(S.Q(k), S.QD(k), p, o);
  if constexpr (F == MDOT) Baked ? casb_mass_matrix_dot(S.Q(k), S.QD(k), o) : cas_mass_matrix_dot(S.Q(k), S.QD(k), p, o);
  if constexpr (F == SLOTINE_LI) cas_slotine_li(S.Q(k), S.QD(k), S.QD((k + 1) % S.count), S.QDD(k), S.pin_params, o);
  if constexpr (F == FD) Baked ? casb_fd(S.Q(k), S.QD(k), S.TAU(k), o) : cas_fd(S.Q(k), S.QD(k), S.TAU(k), p, o);
  if constexpr (F == RNEA_DERIVATIVES)
    Baked ? casb_rnea_derivatives(S.Q(k), S.QD(k), S.QDD(k), o) : cas_rnea_derivatives(S.Q(k), S.QD(k), S.QDD(k), p, o);
  if constexpr (F == FD_DERIVATIVES)
    Baked ? casb_fd_derivatives(S.Q(k), S.QD(k), S.TAU(k), o) : cas_fd_derivatives(S.Q(k), S.QD(k), S.TAU(k), p, o);
  return o[0] + o[N - 1];
}

template <int F>
double pinocchio_call(Setup &S, int k) {
  const double *a = nullptr, *b = nullptr;
  if constexpr (F == CORIOLIS) a = pin_coriolis(S.pin, S.Q(k), S.QD(k));
  if constexpr (F == MDOT) {
    a = pin_coriolis(S.pin, S.Q(k), S.QD(k));
    double *o = S.out.data();
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) o[i * N + j] = a[i + j * N] + a[j + i * N];
    a = o;
  }
  if constexpr (F == SLOTINE_LI) a = pin_regressor(S.pin, S.Q(k), S.QD(k), S.QDD(k));
  if constexpr (F == FD) a = pin_aba(S.pin, S.Q(k), S.QD(k), S.TAU(k));
  if constexpr (F == RNEA_DERIVATIVES) pin_rnea_derivatives(S.pin, S.Q(k), S.QD(k), S.QDD(k), &a, &b);
  if constexpr (F == FD_DERIVATIVES) pin_aba_derivatives(S.pin, S.Q(k), S.QD(k), S.TAU(k), &a, &b);
  return a[0] + a[N - 1] + (b ? b[0] : 0.0);
}

double rel(double a, double b) { return std::fabs(a - b) / std::max(1.0, std::fabs(b)); }

// Pinocchio's value in dyngen's layout (row-major matrices, [dq | dv] blocks side by side);
// for the Slotine-Li regressor: tau = rnea(q, qd, qdd), against which Y(q, qd, qd, qdd) p is checked.
template <int F>
void reference(Setup &S, int k, std::vector<double> &r) {
  const double *a = nullptr, *b = nullptr;
  if constexpr (F == CORIOLIS || F == MDOT) {
    a = pin_coriolis(S.pin, S.Q(k), S.QD(k));
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) r[i * N + j] = F == CORIOLIS ? a[i + j * N] : a[i + j * N] + a[j + i * N];
  }
  if constexpr (F == SLOTINE_LI) std::copy_n(pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k)), N, r.begin());
  if constexpr (F == FD) std::copy_n(pin_aba(S.pin, S.Q(k), S.QD(k), S.TAU(k)), N, r.begin());
  if constexpr (F == RNEA_DERIVATIVES || F == FD_DERIVATIVES) {
    if constexpr (F == RNEA_DERIVATIVES) pin_rnea_derivatives(S.pin, S.Q(k), S.QD(k), S.QDD(k), &a, &b);
    else pin_aba_derivatives(S.pin, S.Q(k), S.QD(k), S.TAU(k), &a, &b);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) r[i * 2 * N + j] = a[i * N + j], r[i * 2 * N + N + j] = b[i * N + j];
  }
}

constexpr int out_size(int f) { return f == CORIOLIS || f == MDOT ? N * N : f == FD || f == SLOTINE_LI ? N : 2 * N * N; }

// side 0 dyngen, 1 CasADi, 2 CasADi baked: its output for state k in dyngen's layout (Slotine-Li: Y(q, qd, qd, qdd) p).
template <int F>
void output(Setup &S, int k, int side, std::vector<double> &o) {
  if constexpr (F == SLOTINE_LI) {
    std::vector<double> Y(N * std::max(N_PI_FULL, 10 * N));
    const int cols = side == 0 ? N_PI_FULL : 10 * N;
    const double *p = side == 0 ? S.pi : S.pin_params;
    if (side == 0) ARM(regressor_slotine_li)(S.Q(k), S.QD(k), S.QD(k), S.QDD(k), Y.data());
    else cas_slotine_li(S.Q(k), S.QD(k), S.QD(k), S.QDD(k), S.pin_params, Y.data());
    for (int i = 0; i < N; ++i) {
      double t = 0.0;
      for (int c = 0; c < cols; ++c) t += Y[i * cols + c] * p[c];
      o[i] = t;
    }
  } else {
    if (side == 0) dyngen_call<F>(S, k);
    if (side == 1) casadi_call<F, false>(S, k);
    if (side == 2) casadi_call<F, true>(S, k);
    std::copy_n(S.out.begin(), out_size(F), o.begin());
  }
}

// The forward dynamics and its derivatives are M^-1 times a vector or matrix: a solve's rounding
// error is relative to the size of the whole result (normwise, about cond(M) u |x|), not to each
// entry, so an entry much smaller than the largest one of the same state is compared on the
// result's scale: |a - b| / max(1, max_i |b_i|). Every other function: entry by entry, as rel.
constexpr bool normwise(int f) { return f == FD || f == FD_DERIVATIVES; }

template <int F>
bool verify_one(Setup &S) {
  double err[3] = {0.0, 0.0, 0.0};
  std::vector<double> r(2 * N * N), o(2 * N * N);
  for (int k = 0; k < S.count; ++k) {
    reference<F>(S, k, r);
    double size = 1.0;
    if (normwise(F))
      for (int i = 0; i < out_size(F); ++i) size = std::max(size, std::fabs(r[i]));
    for (int side = 0; side < 3; ++side) {
      output<F>(S, k, side, o);
      for (int i = 0; i < out_size(F); ++i)
        err[side] = std::max(err[side], normwise(F) ? std::fabs(o[i] - r[i]) / size : rel(o[i], r[i]));
    }
  }
  std::printf("VERIFY %s %.3e %.3e %.3e\n", kNames[F], err[0], err[1], err[2]);
  return err[0] <= 1e-9 && err[1] <= 1e-9 && err[2] <= 1e-9;
}

// Every function of every side against Pinocchio on every state.
bool verify(Setup &S) {
  bool ok = verify_one<CORIOLIS>(S);
  ok = verify_one<MDOT>(S) && ok;
  ok = verify_one<SLOTINE_LI>(S) && ok;
  ok = verify_one<FD>(S) && ok;
  ok = verify_one<RNEA_DERIVATIVES>(S) && ok;
  return verify_one<FD_DERIVATIVES>(S) && ok;
}

using Clock = std::chrono::steady_clock;

template <class F>
double batch_ns(F f, int count) {
  double acc = 0.0;
  const auto t0 = Clock::now();
  for (int k = 0; k < count; ++k) acc += f(k);
  g_sink = acc;
  return std::chrono::duration<double, std::nano>(Clock::now() - t0).count() / count;
}

template <int F>
double side_call(Setup &S, int side, int k) {
  switch (side) {
    case 0: return dyngen_call<F>(S, k);
    case 1: return pinocchio_call<F>(S, k);
    case 2: return casadi_call<F, false>(S, k);
    default: return casadi_call<F, true>(S, k);
  }
}

template <int F>
void time_pair(Setup &S, int batches) {
  std::vector<double> t[4];
  for (int b = 0; b < batches; ++b)  // interleaved batches
    for (int side = 0; side < 4; ++side) t[side].push_back(batch_ns([&](int k) { return side_call<F>(S, side, k); }, S.count));
  std::printf("TIME %s", kNames[F]);
  for (auto &v : t) {
    std::sort(v.begin(), v.end());
    std::printf(" %.1f", v[v.size() / 2]);
  }
  std::printf("\n");
}

template <int F>
double calls(Setup &S, int side, long n) {
  double acc = 0.0;
  for (long c = 0; c < n; ++c) acc += side_call<F>(S, side, (int)(c % S.count));
  return acc;
}

}  // namespace

int main(int argc, char **argv) {
  if (argc < 4) return 1;
  const std::string mode = argv[1];
  Setup S;
  if (!setup(argv[2], std::atoi(argv[3]), S)) return 2;
  if (mode == "verify") return verify(S) ? 0 : 3;
  if (mode == "time" && argc == 5) {
    const int batches = std::atoi(argv[4]);
    time_pair<CORIOLIS>(S, batches);
    time_pair<MDOT>(S, batches);
    time_pair<SLOTINE_LI>(S, batches);
    time_pair<FD>(S, batches);
    time_pair<RNEA_DERIVATIVES>(S, batches);
    time_pair<FD_DERIVATIVES>(S, batches);
    return 0;
  }
  if (mode == "callgrind" && argc == 7) {
    const std::string fn = argv[4];
    const char *const sides[4] = {"dyngen", "pinocchio", "casadi", "casadi_baked"};
    int dyn = -1;
    for (int i = 0; i < 4; ++i)
      if (std::strcmp(argv[5], sides[i]) == 0) dyn = i;
    if (dyn < 0) return 1;
    const long n = std::atol(argv[6]);
    int f = -1;
    for (int i = 0; i < N_FN; ++i)
      if (fn == kNames[i]) f = i;
    switch (f) {
      case CORIOLIS: g_sink = calls<CORIOLIS>(S, dyn, n); break;
      case MDOT: g_sink = calls<MDOT>(S, dyn, n); break;
      case SLOTINE_LI: g_sink = calls<SLOTINE_LI>(S, dyn, n); break;
      case FD: g_sink = calls<FD>(S, dyn, n); break;
      case RNEA_DERIVATIVES: g_sink = calls<RNEA_DERIVATIVES>(S, dyn, n); break;
      case FD_DERIVATIVES: g_sink = calls<FD_DERIVATIVES>(S, dyn, n); break;
      default: return 1;
    }
    return 0;
  }
  return 1;
}
