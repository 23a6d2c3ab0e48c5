// Timing harness of bench_dynamics.py: generated C (dyngen) against Pinocchio on the same
// model, the same random states, the same compiler and flags.
//
// "arms.inc" is written by bench_dynamics.py: one struct per arm wrapping the generated
// functions (direct calls), its sizes, nominal dynamic parameters p and joint ranges, and
// BENCH_ARMS(X) listing the structs.
//
//   harness time      MODELS_DIR STATES BATCHES WARMUP
//       verify on every state, then per arm and function print
//       TIME <arm> <function> <dyngen ns/call> <pinocchio ns/call>   (medians over batches)
//       TIME <arm> <function> <dyngen> <pinocchio> <casadi> <casadi baked>   (ns/call, nan: no such side)
//   harness callgrind MODELS_DIR STATES ARM FUNCTION SIDE CALLS
//       the same set-up (model, states, a short verification that calls every function),
//       then CALLS calls of one function on one side (CALLS = 0: the baseline run).
// SIDE: dyngen, pinocchio, casadi (CasADi-generated C of a plain Newton-Euler over SX with the
// body parameters as an input, bench/casadi_side.py) or casadi_baked (the same, parameters
// baked in as numbers); the CasADi sides exist for rnea, gravity, mass_matrix and forward_dynamics.
//
// The compared pairs (FUNCTION):
//   rnea         <arm>_rnea                                vs pinocchio::rnea
//   gravity      <arm>_gravity                             vs computeGeneralizedGravity
//   yg_pig       <arm>_regressor_gravity, then Y_g pi_g    vs computeGeneralizedGravity
//   mass_matrix  <arm>_mass_matrix                         vs crba
//   ym_pim       <arm>_regressor_inertia, then Y_m pi_m    vs crba
//   regressor    <arm>_regressor (n x base coefficients)   vs computeJointTorqueRegressor (n x 10n)
//   rnea_nominal <arm>_rnea_nominal (the nominal p folded in) vs pinocchio::rnea (CasADi: as for rnea)
//   forward_dynamics <arm>_forward_dynamics(q, qd, tau)    vs aba (CasADi: casadi.solve(M, tau - rnea(q, qd, 0)),
//                the fd of bench_controller.py); tau = pinocchio::rnea(q, qd, qdd) of the state, so qdd comes back
// pi_g and pi_m are computed once from p (<arm>_pi_gravity / _pi_inertia): they are constants
// of the robot; the matrix-vector product is part of the timed work.
#include "pinocchio_controller.hpp"  // pin_aba; it includes pinocchio_side.hpp

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "arms.inc"

namespace {

volatile double g_sink;  // every call's result feeds this, so no call can be dropped

const double kTolerance = 1e-9;  // |dyngen - pinocchio| / max(1, |pinocchio|)

enum Fn { RNEA, GRAVITY, YG_PIG, MASS_MATRIX, YM_PIM, REGRESSOR, RNEA_NOMINAL, FORWARD_DYNAMICS, N_FN };
enum Side { DYNGEN, PINOCCHIO, CASADI, CASADI_BAKED, N_SIDE };
const char *const kSideNames[N_SIDE] = {"dyngen", "pinocchio", "casadi", "casadi_baked"};
constexpr bool has_side(int f, int side) {
  return side < CASADI || f == RNEA || f == GRAVITY || f == MASS_MATRIX || f == RNEA_NOMINAL || f == FORWARD_DYNAMICS;
}
const char *const kFnNames[N_FN] = {"rnea",   "gravity",   "yg_pig",      "mass_matrix",
                                     "ym_pim", "regressor", "rnea_nominal", "forward_dynamics"};

int fn_from_name(const std::string &name) {
  for (int f = 0; f < N_FN; ++f)
    if (name == kFnNames[f]) return f;
  return -1;
}

struct Config {
  bool timing = true;
  std::string models;
  int states = 1000;
  int batches = 200;
  int warmup = 10;
  std::string arm, side;
  int function = -1;
  long calls = 0;
};

template <class A>
struct Setup {
  PinArm *pin = nullptr;
  std::vector<double> s, pi_g, pi_m, pi_f, pin_params, q, qd, qdd, tau;  // tau: rnea of (q, qd, qdd), FD's input
  std::vector<double> out;  // dyngen outputs: n x n (the largest vector-like output)
  std::vector<double> Y;    // dyngen regressors: the largest of Y_g, Y_m, Y
  int count = 0;
  const double *Q(int k) const { return q.data() + (size_t)k * A::n; }
  const double *QD(int k) const { return qd.data() + (size_t)k * A::n; }
  const double *QDD(int k) const { return qdd.data() + (size_t)k * A::n; }
  const double *TAU(int k) const { return tau.data() + (size_t)k * A::n; }
};

template <class A>
bool make_setup(const Config &cfg, Setup<A> &S) {
  const int n = A::n;
  const std::string path = cfg.models + "/" + A::name + ".model";
  int nv = 0;
  S.pin = pin_load(path.c_str(), &nv);
  if (!S.pin || nv != n) {
    std::fprintf(stderr, "cannot load %s (nv %d, expected %d)\n", path.c_str(), nv, n);
    return false;
  }
  S.s.assign(10 * n, 0.0);
  A::std_from_dyn(A::p, S.s.data());
  S.pi_g.assign(A::n_pi_gravity, 0.0);
  S.pi_m.assign(A::n_pi_inertia, 0.0);
  S.pi_f.assign(A::n_pi_full, 0.0);
  A::pi_gravity(A::p, S.pi_g.data());
  A::pi_inertia(A::p, S.pi_m.data());
  A::pi_full(A::p, S.pi_f.data());
  S.pin_params.assign(10 * n, 0.0);
  pin_parameters(S.pin, S.pin_params.data());
  S.count = cfg.states;
  std::mt19937_64 rng(20240611u);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  S.q.resize((size_t)n * S.count);
  S.qd.resize((size_t)n * S.count);
  S.qdd.resize((size_t)n * S.count);
  for (int k = 0; k < S.count; ++k)
    for (int i = 0; i < n; ++i) {
      S.q[(size_t)k * n + i] = A::qlo[i] + (A::qhi[i] - A::qlo[i]) * unit(rng);
      S.qd[(size_t)k * n + i] = -2.0 + 4.0 * unit(rng);
      S.qdd[(size_t)k * n + i] = -5.0 + 10.0 * unit(rng);
    }
  S.tau.resize((size_t)n * S.count);
  for (int k = 0; k < S.count; ++k) {
    const double *t = pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k));
    std::copy(t, t + n, S.tau.begin() + (size_t)k * n);
  }
  S.out.assign((size_t)n * n, 0.0);
  const size_t ny = std::max({(size_t)n * A::n_pi_gravity, (size_t)A::n_stacked * A::n_pi_inertia,
                              (size_t)n * A::n_pi_full});
  S.Y.assign(ny, 0.0);
  return true;
}

// y = A x, A rows x cols row-major: the plain product a user of the regressors writes.
inline void matvec(const double *A, const double *x, int rows, int cols, double *y) {
  for (int r = 0; r < rows; ++r) {
    double acc = 0.0;
    for (int c = 0; c < cols; ++c) acc += A[(size_t)r * cols + c] * x[c];
    y[r] = acc;
  }
}

// The timed work of one function on one side for state k; writes the comparable output
// (tau, g, the upper triangle of M, or the regressor) and returns a value that depends on
// it. Vector outputs are summed (n to n(n+1)/2 entries, as before). The regressors have
// hundreds to thousands of entries: summing them all would cost more than the dyngen call
// itself, so only their first and last entries feed the sink; the calls are out of line
// (other translation units, no LTO), so they cannot be dropped either way.
template <class A, int F>
inline double dyngen_call(Setup<A> &S, int k) {
  const int n = A::n;
  double acc = 0.0;
  if constexpr (F == RNEA) {
    A::rnea(S.Q(k), S.QD(k), S.QDD(k), S.s.data(), S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == RNEA_NOMINAL) {
    A::rnea_nominal(S.Q(k), S.QD(k), S.QDD(k), S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == FORWARD_DYNAMICS) {
    A::forward_dynamics(S.Q(k), S.QD(k), S.TAU(k), S.s.data(), S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == GRAVITY) {
    A::gravity(S.Q(k), S.s.data(), S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == YG_PIG) {
    A::regressor_gravity(S.Q(k), S.Y.data());
    matvec(S.Y.data(), S.pi_g.data(), n, A::n_pi_gravity, S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == MASS_MATRIX) {
    A::mass_matrix(S.Q(k), S.s.data(), S.out.data());  // row-major, full
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) acc += S.out[(size_t)i * n + j];
  } else if constexpr (F == YM_PIM) {
    A::regressor_inertia(S.Q(k), S.Y.data());  // stacked upper triangle, row by row
    matvec(S.Y.data(), S.pi_m.data(), A::n_stacked, A::n_pi_inertia, S.out.data());
    for (int i = 0; i < A::n_stacked; ++i) acc += S.out[i];
  } else {
    A::regressor(S.Q(k), S.QD(k), S.QDD(k), S.Y.data());  // n x n_pi_full, row-major
    acc = S.Y[0] + S.Y[(size_t)n * A::n_pi_full - 1];
  }
  return acc;
}

// The CasADi functions (casadi_side.py): the same outputs as dyngen's (M full, row-major);
// the parameter variant reads Pinocchio's body parameters (the same model as Pinocchio's).
template <class A, int F, bool Baked>
inline double casadi_call(Setup<A> &S, int k) {
  const int n = A::n;
  double acc = 0.0;
  if constexpr (F == RNEA || F == RNEA_NOMINAL) {
    if constexpr (Baked) A::casb_rnea(S.Q(k), S.QD(k), S.QDD(k), S.out.data());
    else A::cas_rnea(S.Q(k), S.QD(k), S.QDD(k), S.pin_params.data(), S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == FORWARD_DYNAMICS) {
    if constexpr (Baked) A::casb_fd(S.Q(k), S.QD(k), S.TAU(k), S.out.data());
    else A::cas_fd(S.Q(k), S.QD(k), S.TAU(k), S.pin_params.data(), S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == GRAVITY) {
    if constexpr (Baked) A::casb_gravity(S.Q(k), S.out.data());
    else A::cas_gravity(S.Q(k), S.pin_params.data(), S.out.data());
    for (int i = 0; i < n; ++i) acc += S.out[i];
  } else if constexpr (F == MASS_MATRIX) {
    if constexpr (Baked) A::casb_mass_matrix(S.Q(k), S.out.data());
    else A::cas_mass_matrix(S.Q(k), S.pin_params.data(), S.out.data());
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) acc += S.out[(size_t)i * n + j];
  }
  return acc;
}

template <class A, int F>
inline double side_call(Setup<A> &S, int side, int k);

template <class A, int F>
inline double pinocchio_call(Setup<A> &S, int k) {
  const int n = A::n;
  double acc = 0.0;
  if constexpr (F == RNEA || F == RNEA_NOMINAL) {
    const double *t = pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k));
    for (int i = 0; i < n; ++i) acc += t[i];
  } else if constexpr (F == FORWARD_DYNAMICS) {
    const double *qdd = pin_aba(S.pin, S.Q(k), S.QD(k), S.TAU(k));
    for (int i = 0; i < n; ++i) acc += qdd[i];
  } else if constexpr (F == GRAVITY || F == YG_PIG) {
    const double *g = pin_gravity(S.pin, S.Q(k));
    for (int i = 0; i < n; ++i) acc += g[i];
  } else if constexpr (F == MASS_MATRIX || F == YM_PIM) {
    const double *M = pin_crba(S.pin, S.Q(k));  // column-major, upper triangle
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) acc += M[i + (size_t)j * n];
  } else {
    const double *Y = pin_regressor(S.pin, S.Q(k), S.QD(k), S.QDD(k));  // n x 10n, column-major
    acc = Y[0] + Y[(size_t)n * 10 * n - 1];
  }
  return acc;
}

double rel_err(double a, double b) { return std::fabs(a - b) / std::max(1.0, std::fabs(b)); }

// Compares every pair on the first `count` states; prints VERIFY lines. For the regressors:
// dyngen's Y pi_full and Pinocchio's regressor times its own parameters, both against
// pinocchio::rnea (the two regressors have different columns, so they are compared through
// what they are for).
template <class A>
bool verify(Setup<A> &S, int count, bool print) {
  const int n = A::n;
  double err[N_FN + 1] = {0.0};  // the last: Pinocchio's regressor times its parameters vs rnea
  double cas_err[2][N_FN] = {{0.0}};  // CasADi with parameters, baked
  std::vector<double> v((size_t)n * n), tau(n);
  auto upper = [&](const double *M_colmajor, int i, int j) { return M_colmajor[i + (size_t)j * n]; };
  for (int k = 0; k < count; ++k) {
    const double *t = pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k));
    std::copy(t, t + n, tau.begin());
    A::rnea(S.Q(k), S.QD(k), S.QDD(k), S.s.data(), v.data());
    for (int i = 0; i < n; ++i) err[RNEA] = std::max(err[RNEA], rel_err(v[i], tau[i]));
    A::rnea_nominal(S.Q(k), S.QD(k), S.QDD(k), v.data());
    for (int i = 0; i < n; ++i) err[RNEA_NOMINAL] = std::max(err[RNEA_NOMINAL], rel_err(v[i], tau[i]));
    A::regressor(S.Q(k), S.QD(k), S.QDD(k), S.Y.data());
    matvec(S.Y.data(), S.pi_f.data(), n, A::n_pi_full, v.data());
    for (int i = 0; i < n; ++i) err[REGRESSOR] = std::max(err[REGRESSOR], rel_err(v[i], tau[i]));
    const double *Yp = pin_regressor(S.pin, S.Q(k), S.QD(k), S.QDD(k));
    for (int i = 0; i < n; ++i) {
      double acc = 0.0;
      for (int c = 0; c < 10 * n; ++c) acc += Yp[i + (size_t)c * n] * S.pin_params[c];
      err[N_FN] = std::max(err[N_FN], rel_err(acc, tau[i]));
    }

    const double *g = pin_gravity(S.pin, S.Q(k));
    A::gravity(S.Q(k), S.s.data(), v.data());
    for (int i = 0; i < n; ++i) err[GRAVITY] = std::max(err[GRAVITY], rel_err(v[i], g[i]));
    A::regressor_gravity(S.Q(k), S.Y.data());
    matvec(S.Y.data(), S.pi_g.data(), n, A::n_pi_gravity, v.data());
    for (int i = 0; i < n; ++i) err[YG_PIG] = std::max(err[YG_PIG], rel_err(v[i], g[i]));

    const double *M = pin_crba(S.pin, S.Q(k));
    A::mass_matrix(S.Q(k), S.s.data(), v.data());
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j)
        err[MASS_MATRIX] = std::max(err[MASS_MATRIX], rel_err(v[(size_t)i * n + j], upper(M, i, j)));
    A::regressor_inertia(S.Q(k), S.Y.data());
    matvec(S.Y.data(), S.pi_m.data(), A::n_stacked, A::n_pi_inertia, v.data());
    for (int i = 0, r = 0; i < n; ++i)
      for (int j = i; j < n; ++j, ++r) err[YM_PIM] = std::max(err[YM_PIM], rel_err(v[r], upper(M, i, j)));

    const double *a = pin_aba(S.pin, S.Q(k), S.QD(k), S.TAU(k));
    A::forward_dynamics(S.Q(k), S.QD(k), S.TAU(k), S.s.data(), v.data());
    for (int i = 0; i < n; ++i) err[FORWARD_DYNAMICS] = std::max(err[FORWARD_DYNAMICS], rel_err(v[i], a[i]));
  }
  for (int k = 0; k < count; ++k) {  // the CasADi sides against Pinocchio
    const double *t = pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k));
    std::copy(t, t + n, tau.begin());
    A::cas_rnea(S.Q(k), S.QD(k), S.QDD(k), S.pin_params.data(), v.data());
    for (int i = 0; i < n; ++i) cas_err[0][RNEA] = std::max(cas_err[0][RNEA], rel_err(v[i], tau[i]));
    A::casb_rnea(S.Q(k), S.QD(k), S.QDD(k), v.data());
    for (int i = 0; i < n; ++i) cas_err[1][RNEA] = std::max(cas_err[1][RNEA], rel_err(v[i], tau[i]));
    const double *g = pin_gravity(S.pin, S.Q(k));
    std::copy(g, g + n, tau.begin());
    A::cas_gravity(S.Q(k), S.pin_params.data(), v.data());
    for (int i = 0; i < n; ++i) cas_err[0][GRAVITY] = std::max(cas_err[0][GRAVITY], rel_err(v[i], tau[i]));
    A::casb_gravity(S.Q(k), v.data());
    for (int i = 0; i < n; ++i) cas_err[1][GRAVITY] = std::max(cas_err[1][GRAVITY], rel_err(v[i], tau[i]));
    const double *M = pin_crba(S.pin, S.Q(k));
    for (int b = 0; b < 2; ++b) {
      if (b == 0) A::cas_mass_matrix(S.Q(k), S.pin_params.data(), v.data());
      else A::casb_mass_matrix(S.Q(k), v.data());
      for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j)
          cas_err[b][MASS_MATRIX] = std::max(cas_err[b][MASS_MATRIX], rel_err(v[(size_t)i * n + j], upper(M, i, j)));
    }
    const double *a = pin_aba(S.pin, S.Q(k), S.QD(k), S.TAU(k));
    std::copy(a, a + n, tau.begin());
    A::cas_fd(S.Q(k), S.QD(k), S.TAU(k), S.pin_params.data(), v.data());
    for (int i = 0; i < n; ++i)
      cas_err[0][FORWARD_DYNAMICS] = std::max(cas_err[0][FORWARD_DYNAMICS], rel_err(v[i], tau[i]));
    A::casb_fd(S.Q(k), S.QD(k), S.TAU(k), v.data());
    for (int i = 0; i < n; ++i)
      cas_err[1][FORWARD_DYNAMICS] = std::max(cas_err[1][FORWARD_DYNAMICS], rel_err(v[i], tau[i]));
  }
  bool ok = true;
  for (int b = 0; b < 2; ++b)
    for (int f : {RNEA, GRAVITY, MASS_MATRIX, FORWARD_DYNAMICS}) {
      if (print) std::printf("VERIFY %s %s_%s %.3e\n", A::name, b ? "casadi_baked" : "casadi", kFnNames[f], cas_err[b][f]);
      // CasADi's forward dynamics is its symbolic QR solve of M: on the Stanford arm (a slide
      // among the joints) it differs from aba by 1.5e-9 over 1000 states, its own rounding, so
      // that competitor is held to 1e-8 (dyngen's own forward dynamics stays at kTolerance)
      if (!(cas_err[b][f] <= (f == FORWARD_DYNAMICS ? 1e-8 : kTolerance))) {
        std::fprintf(stderr, "%s: CasADi %s disagrees (%.3e)\n", A::name, kFnNames[f], cas_err[b][f]);
        ok = false;
      }
    }
  for (int f = 0; f <= N_FN; ++f) {
    const char *what = f < N_FN ? kFnNames[f] : "pinocchio_regressor";
    if (print) std::printf("VERIFY %s %s %.3e\n", A::name, what, err[f]);
    if (!(err[f] <= kTolerance)) {
      std::fprintf(stderr, "%s: %s disagrees (max relative error %.3e > %.0e)\n", A::name, what, err[f],
                   kTolerance);
      ok = false;
    }
  }
  return ok;
}

using Clock = std::chrono::steady_clock;

template <class F>
double batch_ns(F f, int count) {
  double acc = 0.0;
  const auto t0 = Clock::now();
  for (int k = 0; k < count; ++k) acc += f(k);
  const auto t1 = Clock::now();
  g_sink = acc;
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / count;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Interleaved batches (the order alternates), medians of the per-batch ns/call.
template <class A, int F>
inline double side_call(Setup<A> &S, int side, int k) {
  switch (side) {
    case DYNGEN: return dyngen_call<A, F>(S, k);
    case PINOCCHIO: return pinocchio_call<A, F>(S, k);
    case CASADI: return casadi_call<A, F, false>(S, k);
    default: return casadi_call<A, F, true>(S, k);
  }
}

template <class A, int F>
double batch_of(Setup<A> &S, int side) {
  switch (side) {
    case DYNGEN: return batch_ns([&](int k) { return dyngen_call<A, F>(S, k); }, S.count);
    case PINOCCHIO: return batch_ns([&](int k) { return pinocchio_call<A, F>(S, k); }, S.count);
    case CASADI: return batch_ns([&](int k) { return casadi_call<A, F, false>(S, k); }, S.count);
    default: return batch_ns([&](int k) { return casadi_call<A, F, true>(S, k); }, S.count);
  }
}

// Interleaved batches (the order of the sides rotates), medians of the per-batch ns/call.
template <class A, int F>
void time_pair(const Config &cfg, Setup<A> &S) {
  std::vector<double> t[N_SIDE];
  int sides[N_SIDE], count = 0;
  for (int s = 0; s < N_SIDE; ++s)
    if (has_side(F, s)) sides[count++] = s;
  for (int b = 0; b < cfg.warmup + cfg.batches; ++b)
    for (int r = 0; r < count; ++r) {
      const int side = sides[(b + r) % count];
      const double ns = batch_of<A, F>(S, side);
      if (b >= cfg.warmup) t[side].push_back(ns);
    }
  std::printf("TIME %s %s", A::name, kFnNames[F]);
  for (int s = 0; s < N_SIDE; ++s) std::printf(" %.3f", t[s].empty() ? NAN : median(t[s]));
  std::printf("\n");
  std::fflush(stdout);
}

template <class A, int F>
double call_many(Setup<A> &S, int side, long calls) {
  double acc = 0.0;
  for (long c = 0; c < calls; ++c) {
    const int k = (int)(c % S.count);
    acc += side_call<A, F>(S, side, k);
  }
  return acc;
}

template <class A>
int run(const Config &cfg) {
  if (!cfg.timing && cfg.arm != A::name) return 0;
  Setup<A> S;
  if (!make_setup(cfg, S)) return 2;
  if (!verify(S, cfg.timing ? S.count : std::min(S.count, 10), cfg.timing)) return 3;
  if (cfg.timing) {
    time_pair<A, RNEA>(cfg, S);
    time_pair<A, GRAVITY>(cfg, S);
    time_pair<A, YG_PIG>(cfg, S);
    time_pair<A, MASS_MATRIX>(cfg, S);
    time_pair<A, YM_PIM>(cfg, S);
    time_pair<A, REGRESSOR>(cfg, S);
    time_pair<A, RNEA_NOMINAL>(cfg, S);
    time_pair<A, FORWARD_DYNAMICS>(cfg, S);
  } else {
    int dyn = 0;
    while (dyn < N_SIDE && cfg.side != kSideNames[dyn]) ++dyn;
    switch (cfg.function) {
      case RNEA: g_sink = call_many<A, RNEA>(S, dyn, cfg.calls); break;
      case GRAVITY: g_sink = call_many<A, GRAVITY>(S, dyn, cfg.calls); break;
      case YG_PIG: g_sink = call_many<A, YG_PIG>(S, dyn, cfg.calls); break;
      case MASS_MATRIX: g_sink = call_many<A, MASS_MATRIX>(S, dyn, cfg.calls); break;
      case YM_PIM: g_sink = call_many<A, YM_PIM>(S, dyn, cfg.calls); break;
      case RNEA_NOMINAL: g_sink = call_many<A, RNEA_NOMINAL>(S, dyn, cfg.calls); break;
      case FORWARD_DYNAMICS: g_sink = call_many<A, FORWARD_DYNAMICS>(S, dyn, cfg.calls); break;
      default: g_sink = call_many<A, REGRESSOR>(S, dyn, cfg.calls); break;
    }
  }
  pin_free(S.pin);
  return 0;
}

int usage() {
  std::fprintf(stderr,
               "usage: harness time MODELS_DIR STATES BATCHES WARMUP\n"
               "       harness callgrind MODELS_DIR STATES ARM "
               "{rnea|gravity|yg_pig|mass_matrix|ym_pim|regressor|rnea_nominal|forward_dynamics} "
               "{dyngen|pinocchio|casadi|casadi_baked} CALLS\n");
  return 1;
}

}  // namespace

int main(int argc, char **argv) {
  Config cfg;
  if (argc == 6 && std::strcmp(argv[1], "time") == 0) {
    cfg.models = argv[2];
    cfg.states = std::atoi(argv[3]);
    cfg.batches = std::atoi(argv[4]);
    cfg.warmup = std::atoi(argv[5]);
  } else if (argc == 8 && std::strcmp(argv[1], "callgrind") == 0) {
    cfg.timing = false;
    cfg.models = argv[2];
    cfg.states = std::atoi(argv[3]);
    cfg.arm = argv[4];
    cfg.function = fn_from_name(argv[5]);
    cfg.side = argv[6];
    cfg.calls = std::atol(argv[7]);
    if (cfg.function < 0) return usage();
    bool known = false;
    for (int s = 0; s < N_SIDE; ++s) known = known || cfg.side == kSideNames[s];
    if (!known) return usage();
  } else {
    return usage();
  }
  if (cfg.states < 1 || cfg.batches < 1 || cfg.warmup < 0) return usage();
  int rc = 0;
#define BENCH_RUN(A) \
  if (rc == 0) rc = run<A>(cfg);
  BENCH_ARMS(BENCH_RUN)
#undef BENCH_RUN
  return rc;
}
