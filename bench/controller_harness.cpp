// Harness of bench_controller.py: one arm's generated controller functions against Pinocchio's,
// in one binary, the same compiler and flags. "arm.inc" (written by bench_controller.py) includes
// the arm's header and defines ARM(fn) (its C names), N, P (nominal dynamic parameters), QLO, QHI.
//
//   harness verify    MODEL STATES                     VERIFY <function> <max relative error>
//   harness time      MODEL STATES BATCHES              TIME <function> <dyngen ns> <pinocchio ns>
//   harness callgrind MODEL STATES FUNCTION SIDE CALLS  (CALLS = 0: the baseline run)
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
  double s[10 * N], pi[N_PI_FULL];
  std::vector<double> q, qd, qdd, tau;
  std::vector<double> out = std::vector<double>(N * std::max(2 * N, N_PI_FULL));
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

// Every function against Pinocchio on every state: matrices entry by entry (data.C column-major,
// the derivative blocks RowMatrixXs),
// the Slotine-Li regressor as Y(q, qd, qd, qdd) pi_full against pinocchio::rnea.
bool verify(Setup &S) {
  double err[N_FN] = {0.0};
  std::vector<double> o(N * std::max(2 * N, N_PI_FULL));
  for (int k = 0; k < S.count; ++k) {
    const double *C = pin_coriolis(S.pin, S.Q(k), S.QD(k));
    ARM(coriolis_matrix)(S.Q(k), S.QD(k), S.s, o.data());
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) err[CORIOLIS] = std::max(err[CORIOLIS], rel(o[i * N + j], C[i + j * N]));
    ARM(mass_matrix_derivative)(S.Q(k), S.QD(k), S.s, o.data());
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) err[MDOT] = std::max(err[MDOT], rel(o[i * N + j], C[i + j * N] + C[j + i * N]));
    const double *tau = pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k));
    ARM(regressor_slotine_li)(S.Q(k), S.QD(k), S.QD(k), S.QDD(k), o.data());
    for (int i = 0; i < N; ++i) {
      double t = 0.0;
      for (int c = 0; c < N_PI_FULL; ++c) t += o[i * N_PI_FULL + c] * S.pi[c];
      err[SLOTINE_LI] = std::max(err[SLOTINE_LI], rel(t, tau[i]));
    }
    const double *a = pin_aba(S.pin, S.Q(k), S.QD(k), S.TAU(k));
    ARM(forward_dynamics)(S.Q(k), S.QD(k), S.TAU(k), S.s, o.data());
    for (int i = 0; i < N; ++i) err[FD] = std::max(err[FD], rel(o[i], a[i]));
    const double *dq, *dv;
    pin_rnea_derivatives(S.pin, S.Q(k), S.QD(k), S.QDD(k), &dq, &dv);
    ARM(rnea_derivatives)(S.Q(k), S.QD(k), S.QDD(k), S.s, o.data());
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        err[RNEA_DERIVATIVES] = std::max({err[RNEA_DERIVATIVES], rel(o[i * 2 * N + j], dq[i * N + j]),
                                          rel(o[i * 2 * N + N + j], dv[i * N + j])});
    pin_aba_derivatives(S.pin, S.Q(k), S.QD(k), S.TAU(k), &dq, &dv);
    ARM(forward_dynamics_derivatives)(S.Q(k), S.QD(k), S.TAU(k), S.s, o.data());
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        err[FD_DERIVATIVES] = std::max({err[FD_DERIVATIVES], rel(o[i * 2 * N + j], dq[i * N + j]),
                                        rel(o[i * 2 * N + N + j], dv[i * N + j])});
  }
  bool ok = true;
  for (int f = 0; f < N_FN; ++f) {
    std::printf("VERIFY %s %.3e\n", kNames[f], err[f]);
    ok = ok && err[f] <= 1e-9;
  }
  return ok;
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
void time_pair(Setup &S, int batches) {
  std::vector<double> td, tp;
  for (int b = 0; b < batches; ++b) {
    td.push_back(batch_ns([&](int k) { return dyngen_call<F>(S, k); }, S.count));
    tp.push_back(batch_ns([&](int k) { return pinocchio_call<F>(S, k); }, S.count));
  }
  std::sort(td.begin(), td.end());
  std::sort(tp.begin(), tp.end());
  std::printf("TIME %s %.1f %.1f\n", kNames[F], td[td.size() / 2], tp[tp.size() / 2]);
}

template <int F>
double calls(Setup &S, bool dyngen, long n) {
  double acc = 0.0;
  for (long c = 0; c < n; ++c) acc += dyngen ? dyngen_call<F>(S, (int)(c % S.count)) : pinocchio_call<F>(S, (int)(c % S.count));
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
    const bool dyn = std::strcmp(argv[5], "dyngen") == 0;
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
