// Timing harness of bench_dynamics.py: generated C (dyngen) against Pinocchio on the same
// model, the same random states, the same compiler and flags.
//
// "arms.inc" is written by bench_dynamics.py: one struct per arm wrapping the generated
// functions (direct calls), its nominal dynamic parameters p and joint ranges, and
// BENCH_ARMS(X) listing the structs.
//
//   harness time      MODELS_DIR STATES BATCHES WARMUP
//       verify on every state, then per arm and function print
//       TIME <arm> <function> <dyngen ns/call> <pinocchio ns/call>   (medians over batches)
//   harness callgrind MODELS_DIR STATES ARM FUNCTION SIDE CALLS
//       the same set-up (model, states, a short verification that calls every function),
//       then CALLS calls of one function on one side (CALLS = 0: the baseline run).
#include "pinocchio_side.hpp"

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

volatile double g_sink;  // every output is summed into this, so no call can be dropped

const double kTolerance = 1e-9;  // |dyngen - pinocchio| / max(1, |pinocchio|)

struct Config {
  bool timing = true;
  std::string models;
  int states = 1000;
  int batches = 200;
  int warmup = 10;
  std::string arm, function, side;
  long calls = 0;
};

template <class A>
struct Setup {
  PinArm *pin = nullptr;
  std::vector<double> s, q, qd, qdd;
  std::vector<double> out;  // dyngen output buffer (n x n, the largest)
  int count = 0;
  const double *Q(int k) const { return q.data() + (size_t)k * A::n; }
  const double *QD(int k) const { return qd.data() + (size_t)k * A::n; }
  const double *QDD(int k) const { return qdd.data() + (size_t)k * A::n; }
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
  S.out.assign((size_t)n * n, 0.0);
  return true;
}

// One evaluation of each function on each side; returns the sum of the outputs
// (for the inertia matrix: the upper triangle, which is all crba fills).
template <class A>
inline double dyn_rnea(Setup<A> &S, int k) {
  A::rnea(S.Q(k), S.QD(k), S.QDD(k), S.s.data(), S.out.data());
  double acc = 0.0;
  for (int i = 0; i < A::n; ++i) acc += S.out[i];
  return acc;
}
template <class A>
inline double pin_rnea_(Setup<A> &S, int k) {
  const double *t = pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k));
  double acc = 0.0;
  for (int i = 0; i < A::n; ++i) acc += t[i];
  return acc;
}
template <class A>
inline double dyn_gravity(Setup<A> &S, int k) {
  A::gravity(S.Q(k), S.s.data(), S.out.data());
  double acc = 0.0;
  for (int i = 0; i < A::n; ++i) acc += S.out[i];
  return acc;
}
template <class A>
inline double pin_gravity_(Setup<A> &S, int k) {
  const double *g = pin_gravity(S.pin, S.Q(k));
  double acc = 0.0;
  for (int i = 0; i < A::n; ++i) acc += g[i];
  return acc;
}
template <class A>
inline double dyn_mass(Setup<A> &S, int k) {
  A::mass_matrix(S.Q(k), S.s.data(), S.out.data());  // row-major, full
  double acc = 0.0;
  for (int i = 0; i < A::n; ++i)
    for (int j = i; j < A::n; ++j) acc += S.out[(size_t)i * A::n + j];
  return acc;
}
template <class A>
inline double pin_mass(Setup<A> &S, int k) {
  const double *M = pin_crba(S.pin, S.Q(k));  // column-major, upper triangle
  double acc = 0.0;
  for (int i = 0; i < A::n; ++i)
    for (int j = i; j < A::n; ++j) acc += M[i + (size_t)j * A::n];
  return acc;
}

double rel_err(double a, double b) { return std::fabs(a - b) / std::max(1.0, std::fabs(b)); }

// Compares all three functions on the first `count` states; prints VERIFY lines.
template <class A>
bool verify(Setup<A> &S, int count, bool print) {
  const int n = A::n;
  double e_rnea = 0.0, e_grav = 0.0, e_mass = 0.0;
  std::vector<double> M((size_t)n * n);
  for (int k = 0; k < count; ++k) {
    A::rnea(S.Q(k), S.QD(k), S.QDD(k), S.s.data(), S.out.data());
    const double *t = pin_rnea(S.pin, S.Q(k), S.QD(k), S.QDD(k));
    for (int i = 0; i < n; ++i) e_rnea = std::max(e_rnea, rel_err(S.out[i], t[i]));
    A::gravity(S.Q(k), S.s.data(), S.out.data());
    const double *g = pin_gravity(S.pin, S.Q(k));
    for (int i = 0; i < n; ++i) e_grav = std::max(e_grav, rel_err(S.out[i], g[i]));
    A::mass_matrix(S.Q(k), S.s.data(), M.data());
    const double *P = pin_crba(S.pin, S.Q(k));
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) e_mass = std::max(e_mass, rel_err(M[(size_t)i * n + j], P[i + (size_t)j * n]));
  }
  if (print) {
    std::printf("VERIFY %s rnea %.3e\n", A::name, e_rnea);
    std::printf("VERIFY %s gravity %.3e\n", A::name, e_grav);
    std::printf("VERIFY %s mass_matrix %.3e\n", A::name, e_mass);
  }
  const bool ok = e_rnea <= kTolerance && e_grav <= kTolerance && e_mass <= kTolerance;
  if (!ok)
    std::fprintf(stderr, "%s: dyngen and Pinocchio disagree (max relative error rnea %.3e, gravity %.3e, "
                 "mass matrix %.3e > %.0e)\n", A::name, e_rnea, e_grav, e_mass, kTolerance);
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
template <class FD, class FP>
void time_pair(const Config &cfg, const char *arm, const char *function, int count, FD dyn, FP pin) {
  std::vector<double> td, tp;
  for (int b = 0; b < cfg.warmup + cfg.batches; ++b) {
    double d, p;
    if (b % 2 == 0) {
      d = batch_ns(dyn, count);
      p = batch_ns(pin, count);
    } else {
      p = batch_ns(pin, count);
      d = batch_ns(dyn, count);
    }
    if (b >= cfg.warmup) {
      td.push_back(d);
      tp.push_back(p);
    }
  }
  std::printf("TIME %s %s %.3f %.3f\n", arm, function, median(td), median(tp));
  std::fflush(stdout);
}

template <class A>
int run(const Config &cfg) {
  if (!cfg.timing && cfg.arm != A::name) return 0;
  Setup<A> S;
  if (!make_setup(cfg, S)) return 2;
  if (!verify(S, cfg.timing ? S.count : std::min(S.count, 10), cfg.timing)) return 3;
  if (cfg.timing) {
    time_pair(cfg, A::name, "rnea", S.count, [&](int k) { return dyn_rnea(S, k); },
              [&](int k) { return pin_rnea_(S, k); });
    time_pair(cfg, A::name, "gravity", S.count, [&](int k) { return dyn_gravity(S, k); },
              [&](int k) { return pin_gravity_(S, k); });
    time_pair(cfg, A::name, "mass_matrix", S.count, [&](int k) { return dyn_mass(S, k); },
              [&](int k) { return pin_mass(S, k); });
  } else {
    const bool dyn = cfg.side == "dyngen";
    double acc = 0.0;
    for (long c = 0; c < cfg.calls; ++c) {
      const int k = (int)(c % S.count);
      if (cfg.function == "rnea")
        acc += dyn ? dyn_rnea(S, k) : pin_rnea_(S, k);
      else if (cfg.function == "gravity")
        acc += dyn ? dyn_gravity(S, k) : pin_gravity_(S, k);
      else
        acc += dyn ? dyn_mass(S, k) : pin_mass(S, k);
    }
    g_sink = acc;
  }
  pin_free(S.pin);
  return 0;
}

int usage() {
  std::fprintf(stderr,
               "usage: harness time MODELS_DIR STATES BATCHES WARMUP\n"
               "       harness callgrind MODELS_DIR STATES ARM {rnea|gravity|mass_matrix} {dyngen|pinocchio} CALLS\n");
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
    cfg.function = argv[5];
    cfg.side = argv[6];
    cfg.calls = std::atol(argv[7]);
    if (cfg.function != "rnea" && cfg.function != "gravity" && cfg.function != "mass_matrix") return usage();
    if (cfg.side != "dyngen" && cfg.side != "pinocchio") return usage();
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
