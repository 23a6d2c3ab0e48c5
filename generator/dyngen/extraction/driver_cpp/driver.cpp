// driver.cpp: dyngen's extractor of physically consistent link parameters, for any arm.
//
// A static program: the arm comes in at link time through robot.h (robot.c with the generated
// <robot>_kinds.h, and the generated <robot>_parameters.c). `dyngen extract` compiles this file
// once per user into the per-user cache and links it per arm (extraction/driver.py):
//   c++ -O2 -std=c++17 -I. -I/usr/include/eigen3 -c driver.cpp
//   cc -O2 -std=c99 -I. -I<robot folder> -DDYNGEN_KINDS_H='"<robot>_kinds.h"' -c robot.c <robot>_parameters.c
//   c++ driver.o robot.o <robot>_parameters.o -lnlopt -lpthread -o <robot>_extract
// Run:   <robot>_extract PROBLEM_FILE RESULT_FILE   (both written/read by `dyngen extract`)
//        <robot>_extract --echo PROBLEM_FILE COPY  (writes the problem back as read)
//        <robot>_extract --echo-result RESULT_FILE COPY  (writes the result back as read)
//
// Solves  min_p  sum_b || W_b pi_b(p) - v_b ||^2
//         s.t.   LB <= p <= UB                     (free parameters; the others are fixed)
//                total mass in [lo, hi]            (eq. 18 as a real constraint)
//                lambda_min(tr(I_i)/2 E - I_i) >= margin for every link   (physical consistency:
//                    the inertia about the centre of mass is realisable by a positive density)
//                polynomial identities h(p) = 0    (e.g. eq. 15)
// from many random starts p = LB + (UB - LB) u (eq. 17): a global NLopt algorithm (ISRES) and a
// local refinement in the standard parameters s, where the cost is a convex quadratic: a barrier
// Newton method (StandardBarrier; SLSQP with the generated Jacobians when polynomial identities
// are imposed), restarts in parallel, one seed per restart so that the result does not depend on
// the number of threads. Among near-optimal solutions it then prefers the one closest to the
// reference (nominal) parameters, or, in the first of two stages, the one that fits the next
// stage's targets best (hand_off).
// pi_b are the generated base coefficient functions of <robot>_parameters.c (robot.h).

#include <Eigen/Dense>
#include <nlopt.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "robot.h"

// ==== opens the anonymous namespace; coefficient kinds, Problem and its reader ====================
namespace {

// The arm's size, known at run time (robot.h): every array below that depends on it is sized then.
const int kLinks = dyngen_links;
const int kParameters = 10 * dyngen_links;
// Relative cost at which a local run stops: a relative coefficient error of 1e-12, far below
// what identification resolves.
constexpr double kStopCost = 1e-24;

using Kind = dyngen_kind;  // name, rank, pi(p, pi), jacobian(p, J) of one coefficient kind

struct Block {  // one target: W pi_kind(p) = v
    const Kind *kind;
    Eigen::MatrixXd W;
    Eigen::VectorXd v;
};

struct Term {  // coefficient * prod p[index]
    double coefficient;
    std::vector<int> index;
};

// ---- reading the problem -------------------------------------------------------------------

class Reader {
  public:
    explicit Reader(const std::string &path) : in_(path) {
        if (!in_) throw std::runtime_error("cannot read " + path);
    }
    std::string word() {
        std::string w;
        if (!(in_ >> w)) throw std::runtime_error("problem file ends early");
        return w;
    }
    void expect(const std::string &w) {
        const std::string got = word();
        if (got != w) throw std::runtime_error("problem file: expected '" + w + "', got '" + got + "'");
    }
    double number() { return std::stod(word()); }
    long integer() { return std::stol(word()); }
    Eigen::VectorXd vector(int n) {
        Eigen::VectorXd x(n);
        for (int k = 0; k < n; ++k) x[k] = number();
        return x;
    }

  private:
    std::ifstream in_;
};

const Kind *find_kind(const std::string &name) {
    for (int k = 0; k < dyngen_kind_count; ++k)
        if (name == dyngen_kinds[k].name) return &dyngen_kinds[k];
    throw std::runtime_error("unknown coefficient kind " + name);
}

std::vector<Block> read_blocks(Reader &r) {
    std::vector<Block> blocks;
    for (long b = r.integer(); b > 0; --b) {
        Block block;
        block.kind = find_kind(r.word());
        const long rows = r.integer();
        block.W.resize(rows, block.kind->rank);
        for (long i = 0; i < rows; ++i)
            for (int j = 0; j < block.kind->rank; ++j) block.W(i, j) = r.number();
        block.v = r.vector(static_cast<int>(rows));
        blocks.push_back(block);
    }
    return blocks;
}

std::vector<std::vector<Term>> read_terms(Reader &r) {
    std::vector<std::vector<Term>> polys;
    for (long e = r.integer(); e > 0; --e) {
        std::vector<Term> poly;
        for (long t = r.integer(); t > 0; --t) {
            Term term;
            term.coefficient = r.number();
            for (long f = r.integer(); f > 0; --f) term.index.push_back(static_cast<int>(r.integer()));
            poly.push_back(term);
        }
        polys.push_back(poly);
    }
    return polys;
}

// The Problem struct, its reader and its --echo writer, the Result struct, its writer and its
// --echo-result reader, generated from extraction/protocol.py.
#include "protocol.hpp"

// ==== cost and constraints over the free parameters p (unit box), as NLopt sees them ==============
// ---- objective and constraints over the free parameters ------------------------------------

struct Context {
    const Problem *P;
    double cost_cap = 0;  // for the reference stage: objective (relative cost) <= cost_cap
    // The optimisers see x in the unit box, p_j = LB_j + (UB_j - LB_j) x_k: masses (kg), centres
    // of mass (m) and inertias (kg m^2) differ by orders of magnitude, and SLSQP's quasi-Newton
    // steps stall on such badly scaled variables.
    Eigen::VectorXd full(const double *x) const {
        Eigen::VectorXd p = P->value;
        for (size_t k = 0; k < P->free.size(); ++k) p[P->free[k]] = P->lower[P->free[k]] + span(k) * x[k];
        return p;
    }
    double span(size_t k) const { return P->upper[P->free[k]] - P->lower[P->free[k]]; }
    std::vector<double> unit(const Eigen::VectorXd &p) const {  // the inverse of full()
        std::vector<double> x(P->free.size(), 0.0);
        for (size_t k = 0; k < x.size(); ++k)
            if (span(k) > 0) x[k] = (p[P->free[k]] - P->lower[P->free[k]]) / span(k);
        return x;
    }
};

// sum_b ||W_b pi_b(p) - v_b||^2 and its gradient over all parameters.
double fit_cost(const Problem &P, const Eigen::VectorXd &p, Eigen::VectorXd *gradient) {
    double cost = 0;
    if (gradient) gradient->setZero(kParameters);
    Eigen::VectorXd pi;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J;
    for (const Block &b : P.blocks) {
        pi.resize(b.kind->rank);
        b.kind->pi(p.data(), pi.data());
        const Eigen::VectorXd r = b.W * pi - b.v;
        cost += r.squaredNorm();
        if (gradient) {
            J.resize(b.kind->rank, kParameters);
            b.kind->jacobian(p.data(), J.data());
            *gradient += 2.0 * J.transpose() * (b.W.transpose() * r);
        }
    }
    return cost;
}

// The relative cost over the unit box (both scalings keep SLSQP's tolerances meaningful).
double objective(unsigned n, const double *x, double *grad, void *data) {
    const Context &c = *static_cast<Context *>(data);
    Eigen::VectorXd g;
    const double cost = fit_cost(*c.P, c.full(x), grad ? &g : nullptr);
    if (grad)
        for (unsigned k = 0; k < n; ++k) grad[k] = g[c.P->free[k]] * c.span(k) / c.P->cost_scale;
    return cost / c.P->cost_scale;
}

// Distance to the reference parameters (the second, preference stage).
double distance(unsigned n, const double *x, double *grad, void *data) {
    const Context &c = *static_cast<Context *>(data);
    double d = 0;
    for (unsigned k = 0; k < n; ++k) {
        const int j = c.P->free[k];
        const double e = c.P->lower[j] + c.span(k) * x[k] - c.P->reference[j];
        d += c.P->weight[j] * e * e;
        if (grad) grad[k] = 2.0 * c.P->weight[j] * e * c.span(k);
    }
    return d;
}

double cost_cap_constraint(unsigned n, const double *x, double *grad, void *data) {
    const Context &c = *static_cast<Context *>(data);
    return objective(n, x, grad, data) - c.cost_cap;
}

Eigen::Matrix3d density_matrix(const Eigen::VectorXd &p, int link) {
    const double *I = p.data() + 10 * link + 4;  // xx, xy, xz, yy, yz, zz about the centre of mass
    Eigen::Matrix3d inertia;
    inertia << I[0], I[1], I[2], I[1], I[3], I[4], I[2], I[4], I[5];
    return 0.5 * inertia.trace() * Eigen::Matrix3d::Identity() - inertia;
}

// d lambda_min / d I = v^T (dSigma/dI) v for xx, xy, xz, yy, yz, zz; v: the eigenvector of lambda_min.
Eigen::Matrix<double, 6, 1> lambda_min_gradient(const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> &eig) {
    const Eigen::Vector3d v = eig.eigenvectors().col(0);
    Eigen::Matrix<double, 6, 1> d;
    d << 0.5 - v[0] * v[0], -2 * v[0] * v[1], -2 * v[0] * v[2], 0.5 - v[1] * v[1], -2 * v[1] * v[2],
        0.5 - v[2] * v[2];
    return d;
}

// m constraints: margin - lambda_min(tr(I)/2 E - I) <= 0, one per link.
void consistency(unsigned m, double *result, unsigned n, const double *x, double *grad, void *data) {
    const Context &c = *static_cast<Context *>(data);
    const Eigen::VectorXd p = c.full(x);
    if (grad) std::fill(grad, grad + static_cast<size_t>(m) * n, 0.0);
    for (int link = 0; link < kLinks; ++link) {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(density_matrix(p, link));
        result[link] = c.P->margin - eig.eigenvalues()[0];
        if (!grad) continue;
        const Eigen::Matrix<double, 6, 1> d = lambda_min_gradient(eig);
        for (unsigned k = 0; k < n; ++k) {
            const int j = c.P->free[k];
            if (j / 10 == link && j % 10 >= 4) grad[link * n + k] = -d[j % 10 - 4];
        }
    }
}

double total_mass(const Eigen::VectorXd &p) {
    double sum = 0;
    for (int link = 0; link < kLinks; ++link) sum += p[10 * link];
    return sum;
}

double mass_above(unsigned n, const double *x, double *grad, void *data) {
    const Context &c = *static_cast<Context *>(data);
    for (unsigned k = 0; grad && k < n; ++k) grad[k] = c.P->free[k] % 10 == 0 ? c.span(k) : 0.0;
    return total_mass(c.full(x)) - c.P->mass_hi;
}

double mass_below(unsigned n, const double *x, double *grad, void *data) {
    const Context &c = *static_cast<Context *>(data);
    for (unsigned k = 0; grad && k < n; ++k) grad[k] = c.P->free[k] % 10 == 0 ? -c.span(k) : 0.0;
    return c.P->mass_lo - total_mass(c.full(x));
}

struct EqualityData {
    const Context *context;
    const std::vector<Term> *poly;
};

// h(p) of a polynomial identity, and dh/dp when asked.
double polynomial(const std::vector<Term> &poly, const Eigen::VectorXd &p, Eigen::VectorXd *gradient) {
    if (gradient) gradient->setZero(kParameters);
    double h = 0;
    for (const Term &t : poly) {
        double product = t.coefficient;
        for (int i : t.index) product *= p[i];
        h += product;
        if (!gradient) continue;
        for (size_t a = 0; a < t.index.size(); ++a) {  // d/dp of the product, factor a removed
            double rest = t.coefficient;
            for (size_t b = 0; b < t.index.size(); ++b)
                if (b != a) rest *= p[t.index[b]];
            (*gradient)[t.index[a]] += rest;
        }
    }
    return h;
}

double equality(unsigned n, const double *x, double *grad, void *data) {
    const EqualityData &e = *static_cast<EqualityData *>(data);
    Eigen::VectorXd g;
    const double h = polynomial(*e.poly, e.context->full(x), grad ? &g : nullptr);
    for (unsigned k = 0; grad && k < n; ++k) grad[k] = g[e.context->P->free[k]] * e.context->span(k);
    return h;
}

// Largest violation of any constraint at p (0 when feasible).
double violation(const Problem &P, const Eigen::VectorXd &p) {
    double worst = 0;
    for (int j = 0; j < kParameters; ++j)
        worst = std::max({worst, P.lower[j] - p[j], p[j] - P.upper[j]});
    for (int link = 0; link < kLinks; ++link) {
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(density_matrix(p, link), Eigen::EigenvaluesOnly);
        worst = std::max(worst, P.margin - eig.eigenvalues()[0]);
    }
    if (P.has_total_mass) worst = std::max({worst, total_mass(p) - P.mass_hi, P.mass_lo - total_mass(p)});
    for (const auto &poly : P.equalities) worst = std::max(worst, std::fabs(polynomial(poly, p, nullptr)));
    return worst;
}

// ---- one optimisation run ------------------------------------------------------------------

struct Outcome {
    Eigen::VectorXd p;
    double cost = std::numeric_limits<double>::infinity();
    double violation = std::numeric_limits<double>::infinity();
};

void add_constraints(nlopt_opt opt, Context &c, std::vector<EqualityData> &eq_data, double tol) {
    std::vector<double> tols(kLinks, tol);
    nlopt_add_inequality_mconstraint(opt, kLinks, consistency, &c, tols.data());
    if (c.P->has_total_mass) {
        nlopt_add_inequality_constraint(opt, mass_above, &c, tol);
        nlopt_add_inequality_constraint(opt, mass_below, &c, tol);
    }
    for (auto &e : eq_data) nlopt_add_equality_constraint(opt, equality, &e, tol);
}

nlopt_opt make(nlopt_algorithm algorithm, const Problem &P) {
    const unsigned n = static_cast<unsigned>(P.free.size());
    nlopt_opt opt = nlopt_create(algorithm, n);
    std::vector<double> lo(n), hi(n);
    for (unsigned k = 0; k < n; ++k) {
        lo[k] = 0.0;
        hi[k] = 1.0;
    }
    nlopt_set_lower_bounds(opt, lo.data());
    nlopt_set_upper_bounds(opt, hi.data());
    return opt;
}

// ==== local refinement by SLSQP in the standard parameters s (with identities) ====================
// ---- local refinement in the standard parameters ---------------------------------------------
// Per link s = (m, h = m c, S = I + m (c^T c E - c c^T)), ordered m, hx, hy, hz, Sxx, Sxy, Sxz,
// Syy, Syz, Szz. The coefficients are linear in s, so the fit cost is a convex quadratic there,
// and so are the constraints that matter most: consistency (a positive semidefinite
// pseudo-inertia), the mass and centre-of-mass bounds (h between LB_c m and UB_c m), the total
// mass. In p the products m c and m c c make local minima: a restart whose wrist mass shrank to
// its lower bound could not fit the first moments again (PUMA 560: 0 of 16 restarts reached a
// relative error of 1e-9 in p, see the benchmark). Only the inertia bounds (and identities) are
// not convex in s. Used when every parameter is free (the joint procedure).

// p of one link from its s, and dp/ds (10x10, row-major) when asked.
void dynamic_from_standard(const double *s, double *p, double *dpds) {
    const double m = s[0], h[3] = {s[1], s[2], s[3]};
    p[0] = m;
    for (int a = 0; a < 3; ++a) p[1 + a] = h[a] / m;
    // I = S - (h^T h E - h h^T) / m; entries xx, xy, xz, yy, yz, zz
    const int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
    for (int e = 0; e < 6; ++e) {
        const int a = row[e], b = col[e];
        const double q = (a == b ? h[0] * h[0] + h[1] * h[1] + h[2] * h[2] : 0.0) - h[a] * h[b];
        p[4 + e] = s[4 + e] - q / m;
        if (!dpds) continue;
        double *d = dpds + 10 * (4 + e);
        std::fill(d, d + 10, 0.0);
        d[0] = q / (m * m);
        for (int k = 0; k < 3; ++k) {
            double dq = (a == b ? 2 * h[k] : 0.0) - (k == a ? h[b] : 0.0) - (k == b ? h[a] : 0.0);
            d[1 + k] = -dq / m;
        }
        d[4 + e] = 1.0;
    }
    if (!dpds) return;
    std::fill(dpds, dpds + 40, 0.0);
    dpds[0] = 1.0;
    for (int a = 0; a < 3; ++a) {
        dpds[10 * (1 + a) + 0] = -h[a] / (m * m);
        dpds[10 * (1 + a) + 1 + a] = 1.0 / m;
    }
}

struct StandardContext {  // the optimiser's y in the unit box: s = lo + span y
    const Problem *P;
    Eigen::VectorXd lo, span;
    explicit StandardContext(const Problem &problem) : P(&problem), lo(kParameters), span(kParameters) {
        // A box around every s the p bounds allow (loose: the constraints below are exact).
        for (int link = 0; link < kLinks; ++link) {
            const int o = 10 * link;
            const double m_lo = P->lower[o], m_hi = P->upper[o];
            double c2_max[3];
            for (int a = 0; a < 3; ++a) {
                const double cl = P->lower[o + 1 + a], cu = P->upper[o + 1 + a];
                const double h1 = std::min({cl * m_lo, cl * m_hi, cu * m_lo, cu * m_hi});
                const double h2 = std::max({cl * m_lo, cl * m_hi, cu * m_lo, cu * m_hi});
                lo[o + 1 + a] = h1;
                span[o + 1 + a] = h2 - h1;
                c2_max[a] = std::max(cl * cl, cu * cu);
            }
            lo[o] = m_lo;
            span[o] = m_hi - m_lo;
            const int row[6] = {0, 0, 0, 1, 1, 2}, col[6] = {0, 1, 2, 1, 2, 2};
            for (int e = 0; e < 6; ++e) {
                const int a = row[e], b = col[e];
                double shift_lo = 0, shift_hi = 0;  // of m (c^T c delta_ab - c_a c_b)
                if (a == b) {
                    shift_hi = m_hi * (c2_max[0] + c2_max[1] + c2_max[2] - c2_max[a]);
                } else {
                    const double cross = m_hi * std::sqrt(c2_max[a] * c2_max[b]);
                    shift_lo = -cross;
                    shift_hi = cross;
                }
                lo[o + 4 + e] = P->lower[o + 4 + e] + shift_lo;
                span[o + 4 + e] = P->upper[o + 4 + e] + shift_hi - lo[o + 4 + e];
            }
        }
    }
    // p from y, and dp/dy (block diagonal, one 10x10 row-major block per link) when asked.
    Eigen::VectorXd p_of(const double *y, std::vector<double> *dpdy = nullptr) const {
        Eigen::VectorXd p(kParameters);
        if (dpdy) dpdy->assign(static_cast<size_t>(kLinks) * 100, 0.0);
        for (int link = 0; link < kLinks; ++link) {
            double s[10];
            for (int k = 0; k < 10; ++k) s[k] = lo[10 * link + k] + span[10 * link + k] * y[10 * link + k];
            double *block = dpdy ? dpdy->data() + 100 * link : nullptr;
            dynamic_from_standard(s, p.data() + 10 * link, block);
            if (block)
                for (int b = 0; b < 10; ++b)
                    for (int a = 0; a < 10; ++a) block[10 * b + a] *= span[10 * link + a];
        }
        return p;
    }
    std::vector<double> y_of(const Eigen::VectorXd &p) const {
        std::vector<double> y(kParameters, 0.0);
        std::vector<double> s(kParameters);
        dyngen_standard_from_dynamic(p.data(), s.data());
        for (int k = 0; k < kParameters; ++k)
            if (span[k] > 0) y[k] = std::clamp((s[k] - lo[k]) / span[k], 0.0, 1.0);
        return y;
    }
    // d f/d y from d f/d p.
    void chain(const Eigen::VectorXd &dfdp, const std::vector<double> &dpdy, double *out) const {
        for (int link = 0; link < kLinks; ++link)
            for (int a = 0; a < 10; ++a) {
                double sum = 0;
                for (int b = 0; b < 10; ++b) sum += dfdp[10 * link + b] * dpdy[100 * link + 10 * b + a];
                out[10 * link + a] = sum;
            }
    }
};

double standard_objective(unsigned, const double *y, double *grad, void *data) {
    const StandardContext &c = *static_cast<StandardContext *>(data);
    std::vector<double> dpdy;
    const Eigen::VectorXd p = c.p_of(y, grad ? &dpdy : nullptr);
    Eigen::VectorXd g;
    const double cost = fit_cost(*c.P, p, grad ? &g : nullptr);
    if (grad) {
        c.chain(g, dpdy, grad);
        for (int k = 0; k < kParameters; ++k) grad[k] /= c.P->cost_scale;
    }
    return cost / c.P->cost_scale;
}

// Per link, 19 constraints <= 0: consistency, the centre-of-mass bounds as LB_c m - h and
// h - UB_c m (linear in s), and the inertia bounds LB_I - I(s), I(s) - UB_I.
constexpr int kPerLinkConstraints = 19;
void standard_constraints(unsigned m, double *result, unsigned n, const double *y, double *grad, void *data) {
    const StandardContext &c = *static_cast<StandardContext *>(data);
    const Problem &P = *c.P;
    std::vector<double> dpdy;
    const Eigen::VectorXd p = c.p_of(y, grad ? &dpdy : nullptr);
    if (grad) std::fill(grad, grad + static_cast<size_t>(m) * n, 0.0);
    for (int link = 0; link < kLinks; ++link) {
        const int o = 10 * link, first = kPerLinkConstraints * link;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(density_matrix(p, link));
        result[first] = P.margin - eig.eigenvalues()[0];
        double s[10];
        for (int k = 0; k < 10; ++k) s[k] = c.lo[o + k] + c.span[o + k] * y[o + k];
        for (int a = 0; a < 3; ++a) {
            result[first + 1 + 2 * a] = P.lower[o + 1 + a] * s[0] - s[1 + a];
            result[first + 2 + 2 * a] = s[1 + a] - P.upper[o + 1 + a] * s[0];
        }
        for (int e = 0; e < 6; ++e) {
            result[first + 7 + 2 * e] = P.lower[o + 4 + e] - p[o + 4 + e];
            result[first + 8 + 2 * e] = p[o + 4 + e] - P.upper[o + 4 + e];
        }
        if (!grad) continue;
        const double *J = dpdy.data() + 100 * link;  // dp/dy of this link
        auto row = [&](int r) { return grad + static_cast<size_t>(first + r) * n + o; };
        const Eigen::Matrix<double, 6, 1> dl = lambda_min_gradient(eig);
        for (int a = 0; a < 10; ++a) {
            double sum = 0;
            for (int e = 0; e < 6; ++e) sum += dl[e] * J[10 * (4 + e) + a];
            row(0)[a] = -sum;
        }
        for (int a = 0; a < 3; ++a) {
            row(1 + 2 * a)[0] = P.lower[o + 1 + a] * c.span[o];
            row(1 + 2 * a)[1 + a] = -c.span[o + 1 + a];
            row(2 + 2 * a)[0] = -P.upper[o + 1 + a] * c.span[o];
            row(2 + 2 * a)[1 + a] = c.span[o + 1 + a];
        }
        for (int e = 0; e < 6; ++e)
            for (int a = 0; a < 10; ++a) {
                row(7 + 2 * e)[a] = -J[10 * (4 + e) + a];
                row(8 + 2 * e)[a] = J[10 * (4 + e) + a];
            }
    }
}

double standard_total_mass(unsigned n, const double *y, double *grad, void *data) {  // sign * (sum m - bound)
    const auto &[c, sign] = *static_cast<std::pair<const StandardContext *, double> *>(data);
    double total = 0;
    for (int link = 0; link < kLinks; ++link) total += c->lo[10 * link] + c->span[10 * link] * y[10 * link];
    for (unsigned k = 0; grad && k < n; ++k) grad[k] = k % 10 == 0 ? sign * c->span[k] : 0.0;
    return sign > 0 ? total - c->P->mass_hi : c->P->mass_lo - total;
}

struct StandardEquality {
    const StandardContext *context;
    const std::vector<Term> *poly;
};
double standard_equality(unsigned, const double *y, double *grad, void *data) {
    const StandardEquality &e = *static_cast<StandardEquality *>(data);
    std::vector<double> dpdy;
    const Eigen::VectorXd p = e.context->p_of(y, grad ? &dpdy : nullptr);
    Eigen::VectorXd g;
    const double h = polynomial(*e.poly, p, grad ? &g : nullptr);
    if (grad) e.context->chain(g, dpdy, grad);
    return h;
}

// SLSQP over y from the parameters p0; the result back in p, clipped to the bounds (the
// constraints hold to the tolerance in s, which can be a little more in p for a light link).
Eigen::VectorXd standard_local(const Problem &P, const Eigen::VectorXd &p0) {
    StandardContext c(P);
    nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, kParameters);
    nlopt_set_lower_bounds1(opt, 0.0);
    nlopt_set_upper_bounds1(opt, 1.0);
    nlopt_set_min_objective(opt, standard_objective, &c);
    std::vector<double> tols(static_cast<size_t>(kPerLinkConstraints) * kLinks, P.tolerance);
    nlopt_add_inequality_mconstraint(opt, static_cast<unsigned>(tols.size()), standard_constraints, &c, tols.data());
    std::pair<const StandardContext *, double> above{&c, 1.0}, below{&c, -1.0};
    if (P.has_total_mass) {
        nlopt_add_inequality_constraint(opt, standard_total_mass, &above, P.tolerance);
        nlopt_add_inequality_constraint(opt, standard_total_mass, &below, P.tolerance);
    }
    std::vector<StandardEquality> eq;
    for (const auto &poly : P.equalities) eq.push_back({&c, &poly});
    for (auto &e : eq) nlopt_add_equality_constraint(opt, standard_equality, &e, P.tolerance);
    nlopt_set_maxeval(opt, P.local_maxeval);
    nlopt_set_ftol_rel(opt, 1e-15);
    nlopt_set_xtol_rel(opt, 1e-13);
    nlopt_set_stopval(opt, kStopCost);
    std::vector<double> y = c.y_of(p0);
    // SLSQP's quasi-Newton model can go stale on the way (runs stopping at relative errors of
    // 1e-7); a fresh run from where it stopped continues while it still gains.
    double value = HUGE_VAL;
    for (int round = 0; round < 4; ++round) {
        const double before = value;
        nlopt_optimize(opt, y.data(), &value);
        if (!(value < 0.5 * before) || value <= kStopCost) break;
    }
    nlopt_destroy(opt);
    Eigen::VectorXd p = c.p_of(y.data());
    return p.cwiseMax(P.lower).cwiseMin(P.upper);
}

// ==== the barrier method's pieces: pseudo-inertia basis, log barrier, convexified =================
// ---- local refinement in s by a barrier (interior-point) Newton method -------------------------
// In the standard parameters s the fit cost f(s) = ||A s - b||^2 / cost_scale is an exact convex
// quadratic (Hessian 2 A^T A / cost_scale, known), so SLSQP's quasi-Newton model only rediscovers
// it, in hundreds of iterations of O(n^2 m) work each. Newton's method on
//     psi_mu(s) = f(s) / mu - log det J(s) - sum_k log g_k(s)
// with mu -> 0 needs tens of steps instead. J(s) = [[tr(S)/2 E - S - margin E, h], [h^T, m]] is the
// pseudo-inertia less the margin: J > 0 <=> m > 0 and lambda_min(tr(I)/2 E - I) > margin (Schur
// complement), a linear matrix inequality. g_k > 0 are the bounds: linear in s for the mass, the
// centres of mass (h between LB_c m and UB_c m) and the total mass, and I(s) = S - (h^T h E - h h^T)/m
// within the inertia bounds (I_kk >= LB is convex, the others are not: where a link's barrier
// Hessian is indefinite, Newton's method uses its absolute eigenvalues, see convexified). Every iterate is strictly feasible, so the
// point returned satisfies every constraint (still checked by violation()). Parameters fixed by an
// earlier stage (masses, centres of mass) make s affine in the remaining variables z: s = s_fixed + Z z.
// Not used with polynomial identities or fixed inertias (SLSQP handles those). On the example arms
// it takes 30-90 Newton steps per restart where SLSQP took 460-580 evaluations of O(n^2 m) work.

constexpr int kSIndexRow[6] = {0, 0, 0, 1, 1, 2}, kSIndexCol[6] = {0, 1, 2, 1, 2, 2};

using Matrix10 = Eigen::Matrix<double, 10, 10>;
using Vector10 = Eigen::Matrix<double, 10, 1>;

// dJ/ds_a for a = m, hx, hy, hz, Sxx, Sxy, Sxz, Syy, Syz, Szz (J is linear in s).
std::array<Eigen::Matrix4d, 10> pseudo_inertia_basis() {
    std::array<Eigen::Matrix4d, 10> B;
    for (auto &b : B) b.setZero();
    B[0](3, 3) = 1;
    for (int k = 0; k < 3; ++k) B[1 + k](k, 3) = B[1 + k](3, k) = 1;
    for (int e = 0; e < 6; ++e) {
        const int a = kSIndexRow[e], b = kSIndexCol[e];
        if (a == b) {
            B[4 + e].topLeftCorner<3, 3>() = 0.5 * Eigen::Matrix3d::Identity();
            B[4 + e](a, a) = -0.5;
        } else {
            B[4 + e](a, b) = B[4 + e](b, a) = -1;
        }
    }
    return B;
}

// The non-convex inertia bounds can make a link's barrier Hessian indefinite; Newton's method then
// uses its absolute eigenvalues (a descent direction that keeps the curvature's scale).
Matrix10 convexified(const Matrix10 &h) {
    if (Eigen::LLT<Matrix10>(h).info() == Eigen::Success) return h;
    Eigen::SelfAdjointEigenSolver<Matrix10> eig(h);
    const Vector10 lambda = eig.eigenvalues().cwiseAbs().cwiseMax(1e-12 * eig.eigenvalues().cwiseAbs().maxCoeff());
    return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

// -log g with its gradient and Hessian added to (value, grad, hess), from g, dg, d2g; false if g <= 0.
bool add_log_barrier(double g, const Vector10 &dg, const Matrix10 *d2g, double &value, Vector10 &grad,
                     Matrix10 &hess) {
    if (!(g > 0)) return false;
    value -= std::log(g);
    grad -= dg / g;
    hess += dg * dg.transpose() / (g * g);
    if (d2g) hess -= *d2g / g;
    return true;
}

// ==== StandardBarrier: the barrier (interior-point) Newton method in s ============================
class StandardBarrier {
  public:
    // The cost of `blocks` (relative to their norm) under P's bounds and fixed parameters.
    StandardBarrier(const Problem &P, const std::vector<Block> &blocks) : P_(P) {
        usable_ = P.equalities.empty() && place_centre() && map_variables();
        if (!usable_) return;
        linear_cost(blocks);
        usable_ = barrier(variables_of(p_center_), nullptr, nullptr);
    }
    bool usable() const { return usable_; }

    // Keeps only the s whose coefficients A s equal those of p (strictly feasible, the start of
    // solve() from now on): s = s(p) + Z N w with N a basis of the null space of A Z.
    void restrict_to(const StandardBarrier &coefficients, const Eigen::VectorXd &p) {
        const Eigen::MatrixXd AZ = coefficients.A_ * Z_;
        Eigen::JacobiSVD<Eigen::MatrixXd> svd(AZ, Eigen::ComputeFullV);
        svd.setThreshold(1e-12);
        const Eigen::MatrixXd N = svd.matrixV().rightCols(AZ.cols() - svd.rank());
        s_fixed_ = standard_of(p);
        Z_ = Z_ * N;
        identity_map_ = false;
        p_center_ = p;
        map_cost();
        usable_ = usable_ && barrier(Eigen::VectorXd::Zero(Z_.cols()), nullptr, nullptr);
    }

    // From p0 (pulled towards the centre until strictly feasible), the minimiser in p.
    Eigen::VectorXd solve(const Eigen::VectorXd &p0, int max_newton) const {
        Eigen::VectorXd z;
        for (double tau : {0.0, 1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0}) {  // the centre itself is strictly feasible
            z = variables_of((1 - tau) * p0 + tau * p_center_);
            if (barrier(z, nullptr, nullptr)) break;
        }
        const int n = static_cast<int>(z.size());
        const double nu = 1 + 21.0 * kLinks;  // barrier parameter: a 4x4 log det and up to 18 bounds per link
        double f = cost(z);
        double mu = std::max(f, 1e-16) / nu;  // f / mu and the barrier start at comparable sizes
        Eigen::VectorXd grad(n), step(n), trial(n);
        Eigen::MatrixXd hess(n, n);
        int newton = 0;
        while (newton < max_newton && f > kStopCost && mu > 1e-30) {
            for (int inner = 0; inner < 30 && newton < max_newton; ++inner, ++newton) {
                const double psi = value(z, mu, &grad, &hess);
                if (!newton_step(hess, grad, step)) break;
                const double decrement = -grad.dot(step);  // Newton decrement squared
                if (!(decrement > 1e-10)) break;
                bool accepted = false;  // Armijo backtracking; infeasible trials have psi = +inf
                for (double t = 1; t > 1e-18 && !accepted; t *= 0.5) {
                    trial = z + t * step;
                    accepted = value(trial, mu, nullptr, nullptr) <= psi - 0.25 * t * decrement;
                }
                if (!accepted) break;
                z = trial;
                if (decrement < 1e-6) break;
            }
            const double f_new = cost(z);
            // At an inexact optimum f stops falling once the barrier's bound on the gap, nu mu,
            // is tiny beside it; at an exact one f falls with mu until kStopCost.
            const bool settled = nu * mu < 1e-8 * f_new && f_new > 0.5 * f;
            f = f_new;
            if (settled) break;
            mu *= 0.1;
        }
        return dynamic_of(z);
    }

  private:
    // The centre: free parameters at P.center, the fixed ones at P.value, the free masses moved
    // together into the total-mass window. False if the window leaves them no room.
    bool place_centre() {
        std::vector<bool> is_free(kParameters, false);
        for (int j : P_.free) is_free[j] = P_.upper[j] > P_.lower[j];
        p_center_ = P_.value;
        for (int j : P_.free) p_center_[j] = P_.center[j];
        double fixed_mass = 0, lo_free = 0, hi_free = 0;
        for (int link = 0; link < kLinks; ++link) {
            const int o = 10 * link;
            mass_free_[link] = is_free[o];
            for (int a = 0; a < 3; ++a) com_free_[link][a] = is_free[o + 1 + a];
            for (int e = 0; e < 6; ++e)
                if (!is_free[o + 4 + e]) return false;  // a fixed inertia is not affine in s
            if (mass_free_[link]) {
                lo_free += P_.lower[o];
                hi_free += P_.upper[o];
                any_mass_free_ = true;
            } else {
                fixed_mass += P_.value[o];
            }
        }
        if (!P_.has_total_mass || !any_mass_free_) return true;
        const double lo = std::max(P_.mass_lo, fixed_mass + lo_free), hi = std::min(P_.mass_hi, fixed_mass + hi_free);
        if (!(lo < hi)) return false;
        const double alpha = (0.5 * (lo + hi) - fixed_mass - lo_free) / (hi_free - lo_free);
        for (int link = 0; link < kLinks; ++link)
            if (mass_free_[link]) p_center_[10 * link] = P_.lower[10 * link] + alpha * (P_.upper[10 * link] - P_.lower[10 * link]);
        return true;
    }
    // s = s_fixed + Z z. A fixed centre of mass c_a makes h_a = c_a m (part of the mass's column)
    // or, with the mass fixed too, a constant.
    bool map_variables() {
        std::vector<Eigen::VectorXd> columns;
        for (int link = 0; link < kLinks; ++link) {
            const int o = 10 * link;
            if (mass_free_[link]) {
                Eigen::VectorXd col = Eigen::VectorXd::Zero(kParameters);
                col[o] = 1;
                for (int a = 0; a < 3; ++a)
                    if (!com_free_[link][a]) col[o + 1 + a] = P_.value[o + 1 + a];
                columns.push_back(col);
            }
            for (int k = 1; k < 10; ++k)
                if (k >= 4 || com_free_[link][k - 1]) columns.push_back(Eigen::VectorXd::Unit(kParameters, o + k));
        }
        Z_.resize(kParameters, static_cast<int>(columns.size()));
        for (size_t k = 0; k < columns.size(); ++k) Z_.col(static_cast<int>(k)) = columns[k];
        identity_map_ = Z_.cols() == kParameters && Z_.isIdentity();
        s_fixed_ = standard_of(p_center_);  // without the components that depend on z
        for (int r = 0; r < kParameters; ++r)
            if ((Z_.row(r).array() != 0).any()) s_fixed_[r] = 0;
        return Z_.cols() > 0;
    }
    // A and b of f = ||A s - b||^2: pi is linear in s, so dpi/ds = dpi/dp dp/ds at any s is exact
    // (taken at the centre).
    void linear_cost(const std::vector<Block> &blocks) {
        int rows = 0;
        double norm = 0;
        for (const Block &b : blocks) {
            rows += static_cast<int>(b.W.rows());
            norm += b.v.squaredNorm();
        }
        A_.resize(rows, kParameters);
        b_.resize(rows);
        std::vector<double> dpds(100 * kLinks, 0.0);
        const Eigen::VectorXd s = standard_of(p_center_);
        Eigen::VectorXd p(kParameters);
        for (int link = 0; link < kLinks; ++link)
            dynamic_from_standard(s.data() + 10 * link, p.data() + 10 * link, dpds.data() + 100 * link);
        int row = 0;
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> J;
        for (const Block &b : blocks) {
            J.resize(b.kind->rank, kParameters);
            b.kind->jacobian(p_center_.data(), J.data());
            Eigen::MatrixXd K(b.kind->rank, kParameters);
            for (int link = 0; link < kLinks; ++link) {
                Eigen::Map<const Eigen::Matrix<double, 10, 10, Eigen::RowMajor>> dp(dpds.data() + 100 * link);
                K.middleCols<10>(10 * link) = J.middleCols<10>(10 * link) * dp;
            }
            A_.middleRows(row, b.W.rows()) = b.W * K;
            b_.segment(row, b.W.rows()) = b.v;
            row += static_cast<int>(b.W.rows());
        }
        if (norm > 0) {
            A_ /= std::sqrt(norm);
            b_ /= std::sqrt(norm);
        }
        map_cost();
    }
    // The cost in z: its matrix A Z and Hessian 2 (A Z)^T A Z, after A or the map s = s_fixed + Z z changed.
    void map_cost() {
        AZ_ = A_ * Z_;
        G_ = 2.0 * AZ_.transpose() * AZ_;
    }
    Eigen::VectorXd residual(const Eigen::VectorXd &z) const { return A_ * s_fixed_ + AZ_ * z - b_; }
    static Eigen::VectorXd standard_of(const Eigen::VectorXd &p) {
        Eigen::VectorXd s(kParameters);
        dyngen_standard_from_dynamic(p.data(), s.data());
        return s;
    }
    Eigen::VectorXd variables_of(const Eigen::VectorXd &p) const {
        const Eigen::VectorXd s = standard_of(p) - s_fixed_;
        if (identity_map_) return s;
        return Z_.colPivHouseholderQr().solve(s);
    }
    Eigen::VectorXd dynamic_of(const Eigen::VectorXd &z) const {
        const Eigen::VectorXd s = s_fixed_ + Z_ * z;
        Eigen::VectorXd p(kParameters);
        for (int link = 0; link < kLinks; ++link) dynamic_from_standard(s.data() + 10 * link, p.data() + 10 * link, nullptr);
        return p;
    }
    double cost(const Eigen::VectorXd &z) const {
        return residual(z).squaredNorm();
    }
    // psi = f / mu + barrier, with gradient and Hessian in z when asked; +inf outside.
    double value(const Eigen::VectorXd &z, double mu, Eigen::VectorXd *grad, Eigen::MatrixXd *hess) const {
        Eigen::VectorXd gb, r = residual(z);
        Eigen::MatrixXd hb;
        double b = 0;
        if (!barrier(z, grad ? &gb : nullptr, hess ? &hb : nullptr, &b)) return HUGE_VAL;
        if (grad) *grad = 2.0 * AZ_.transpose() * r / mu + gb;
        if (hess) *hess = G_ / mu + hb;
        return r.squaredNorm() / mu + b;
    }
    // Newton step -hess^-1 grad (the Hessian is positive definite but for rounding; a shift if not)
    static bool newton_step(const Eigen::MatrixXd &hess, const Eigen::VectorXd &grad, Eigen::VectorXd &step) {
        const Eigen::VectorXd d = hess.diagonal().cwiseAbs().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
        Eigen::MatrixXd scaled = d.asDiagonal() * hess * d.asDiagonal();
        for (double shift = 0; shift < 1e6; shift = shift == 0 ? 1e-12 : 10 * shift) {
            Eigen::LLT<Eigen::MatrixXd> llt(scaled + shift * Eigen::MatrixXd::Identity(hess.rows(), hess.cols()));
            if (llt.info() != Eigen::Success) continue;
            step = -(d.asDiagonal() * llt.solve(d.asDiagonal() * grad));
            return step.allFinite();
        }
        return false;
    }
    // The barrier at z: -sum log det J - sum log g; false when z is not strictly feasible.
    bool barrier(const Eigen::VectorXd &z, Eigen::VectorXd *grad, Eigen::MatrixXd *hess,
                 double *value_out = nullptr) const {
        static const std::array<Eigen::Matrix4d, 10> B = pseudo_inertia_basis();
        const Eigen::VectorXd s = s_fixed_ + Z_ * z;
        Eigen::VectorXd gs = Eigen::VectorXd::Zero(kParameters);
        Eigen::MatrixXd hs;
        if (hess) hs = Eigen::MatrixXd::Zero(kParameters, kParameters);
        double total = 0;
        for (int link = 0; link < kLinks; ++link) {
            const int o = 10 * link;
            const double *x = s.data() + o;
            const double m = x[0];
            if (!(m > 0)) return false;
            double value = 0;
            Vector10 g = Vector10::Zero();
            Matrix10 h = Matrix10::Zero();
            // consistency: -log det J
            Eigen::Matrix4d Jm = Eigen::Matrix4d::Zero();
            for (int a = 0; a < 10; ++a) Jm += x[a] * B[a];
            Jm.topLeftCorner<3, 3>() -= P_.margin * Eigen::Matrix3d::Identity();
            Eigen::LLT<Eigen::Matrix4d> llt(Jm);
            if (llt.info() != Eigen::Success) return false;
            const Eigen::Matrix4d L = llt.matrixL();
            for (int k = 0; k < 4; ++k) {
                if (!(L(k, k) > 0)) return false;
                value -= 2 * std::log(L(k, k));
            }
            const Eigen::Matrix4d Jinv = llt.solve(Eigen::Matrix4d::Identity());
            std::array<Eigen::Matrix4d, 10> M;
            for (int a = 0; a < 10; ++a) {
                M[a] = Jinv * B[a];
                g[a] -= M[a].trace();
            }
            for (int a = 0; a < 10; ++a)
                for (int b = a; b < 10; ++b) h(a, b) = h(b, a) = (M[a].array() * M[b].transpose().array()).sum();
            // the mass and centre-of-mass bounds (linear in s)
            if (mass_free_[link]) {
                if (!add_log_barrier(m - P_.lower[o], Vector10::Unit(0), nullptr, value, g, h)) return false;
                if (!add_log_barrier(P_.upper[o] - m, -Vector10::Unit(0), nullptr, value, g, h)) return false;
            }
            for (int a = 0; a < 3; ++a) {
                if (!com_free_[link][a]) continue;
                Vector10 d = Vector10::Zero();
                d[1 + a] = 1;
                d[0] = -P_.lower[o + 1 + a];
                if (!add_log_barrier(x[1 + a] - P_.lower[o + 1 + a] * m, d, nullptr, value, g, h)) return false;
                d[1 + a] = -1;
                d[0] = P_.upper[o + 1 + a];
                if (!add_log_barrier(P_.upper[o + 1 + a] * m - x[1 + a], d, nullptr, value, g, h)) return false;
            }
            // the inertia bounds: I_e = S_e - q_e(h) / m, q_e = (a == b) h^T h - h_a h_b
            for (int e = 0; e < 6; ++e) {
                const int a = kSIndexRow[e], b = kSIndexCol[e];
                const double hh[3] = {x[1], x[2], x[3]};
                const double q = (a == b ? hh[0] * hh[0] + hh[1] * hh[1] + hh[2] * hh[2] : 0.0) - hh[a] * hh[b];
                const double inertia = x[4 + e] - q / m;
                Vector10 d = Vector10::Zero();
                Matrix10 d2 = Matrix10::Zero();
                d[0] = q / (m * m);
                d2(0, 0) = -2 * q / (m * m * m);
                for (int k = 0; k < 3; ++k) {
                    const double dq = (a == b ? 2 * hh[k] : 0.0) - (k == a ? hh[b] : 0.0) - (k == b ? hh[a] : 0.0);
                    d[1 + k] = -dq / m;
                    d2(0, 1 + k) = d2(1 + k, 0) = dq / (m * m);
                    for (int l = 0; l < 3; ++l) {
                        const double d2q = (a == b && k == l ? 2.0 : 0.0) - (k == a && l == b ? 1.0 : 0.0) -
                                            (k == b && l == a ? 1.0 : 0.0);
                        d2(1 + k, 1 + l) = -d2q / m;
                    }
                }
                d[4 + e] = 1;
                if (!add_log_barrier(inertia - P_.lower[o + 4 + e], d, &d2, value, g, h)) return false;
                const Vector10 dn = -d;
                const Matrix10 d2n = -d2;
                if (!add_log_barrier(P_.upper[o + 4 + e] - inertia, dn, &d2n, value, g, h)) return false;
            }
            total += value;
            gs.segment<10>(o) += g;
            if (hess) hs.block<10, 10>(o, o) += convexified(h);
        }
        if (P_.has_total_mass && any_mass_free_) {
            double mass = 0;
            for (int link = 0; link < kLinks; ++link) mass += s[10 * link];
            const double lo = mass - P_.mass_lo, hi = P_.mass_hi - mass;
            if (!(lo > 0) || !(hi > 0)) return false;
            total -= std::log(lo);
            total -= std::log(hi);
            for (int a = 0; a < kLinks; ++a) {
                gs[10 * a] += -1 / lo + 1 / hi;
                if (hess)
                    for (int b = 0; b < kLinks; ++b) hs(10 * a, 10 * b) += 1 / (lo * lo) + 1 / (hi * hi);
            }
        }
        if (value_out) *value_out = total;
        if (grad) *grad = identity_map_ ? gs : Eigen::VectorXd(Z_.transpose() * gs);
        if (hess) *hess = identity_map_ ? hs : Eigen::MatrixXd(Z_.transpose() * hs * Z_);
        return true;
    }

    const Problem &P_;
    bool usable_ = true, identity_map_ = true, any_mass_free_ = false;
    std::vector<char> mass_free_ = std::vector<char>(kLinks, 0);
    std::vector<std::array<bool, 3>> com_free_ = std::vector<std::array<bool, 3>>(kLinks, {false, false, false});
    Eigen::VectorXd p_center_, s_fixed_, b_;
    Eigen::MatrixXd Z_, A_, AZ_, G_;
};

// ==== one restart: random start, ISRES, local refinement, basin hopping ===========================
Outcome run_restart(const Problem &P, const StandardBarrier &barrier, int restart) {
    Context c{&P};
    std::vector<EqualityData> eq;
    for (const auto &poly : P.equalities) eq.push_back({&c, &poly});
    const unsigned n = static_cast<unsigned>(P.free.size());
    std::mt19937_64 rng(P.seed * 1000003ULL + static_cast<unsigned long>(restart));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> x(n);
    for (unsigned k = 0; k < n; ++k) x[k] = u(rng);  // eq. (17) in the unit box
    double value = 0;
    if (P.global_algorithm == "isres" && P.global_maxeval > 0) {
        nlopt_srand(P.seed * 7919ULL + static_cast<unsigned long>(restart));  // thread-local in NLopt
        nlopt_opt global = make(NLOPT_GN_ISRES, P);
        nlopt_set_min_objective(global, objective, &c);
        add_constraints(global, c, eq, P.tolerance);
        nlopt_set_maxeval(global, P.global_maxeval);
        nlopt_optimize(global, x.data(), &value);
        nlopt_destroy(global);
    }
    // The local refinement: the barrier method in s; without it (identities, fixed inertias) SLSQP,
    // in s when every parameter is free, else in p.
    const bool in_standard = P.free.size() == static_cast<size_t>(kParameters);
    nlopt_opt local = nullptr;  // SLSQP in p, built only where it is used
    if (!barrier.usable() && !in_standard) {
        local = make(NLOPT_LD_SLSQP, P);
        nlopt_set_min_objective(local, objective, &c);
        add_constraints(local, c, eq, P.tolerance);
        nlopt_set_maxeval(local, P.local_maxeval);
        nlopt_set_ftol_rel(local, 1e-15);
        nlopt_set_xtol_rel(local, 1e-13);
        nlopt_set_stopval(local, kStopCost);
    }
    auto settle = [&](std::vector<double> &y) {
        Outcome o;
        if (barrier.usable()) {
            o.p = barrier.solve(c.full(y.data()), P.local_maxeval);
        } else if (in_standard) {
            o.p = standard_local(P, c.full(y.data()));
        } else {
            nlopt_optimize(local, y.data(), &value);
            o.p = c.full(y.data());
        }
        o.cost = fit_cost(P, o.p, nullptr);
        o.violation = violation(P, o.p);
        return o;
    };
    Outcome out = settle(x);
    // Basin hopping: kick the local minimum by hop_size of each range and settle again.
    std::normal_distribution<double> kick(0.0, P.hop_size);
    for (int h = 0; h < P.hops; ++h) {
        std::vector<double> y = c.unit(out.p);
        for (unsigned k = 0; k < n; ++k) y[k] = std::clamp(y[k] + kick(rng), 0.0, 1.0);
        const Outcome hop = settle(y);
        const bool feasible = hop.violation <= P.tolerance, was = out.violation <= P.tolerance;
        if ((feasible && (!was || hop.cost < out.cost)) || (!feasible && !was && hop.violation < out.violation))
            out = hop;
    }
    if (local) nlopt_destroy(local);
    return out;
}

// ==== among near-optimal fits: prefer_reference, or hand_off in a two-stage run ===================
// Among solutions with cost <= cap, the one closest to the reference parameters.
Outcome prefer_reference(const Problem &P, const Outcome &best) {
    Context c{&P};
    // Almost no slack: the cost is relative to all blocks together, so a looser cap would let a
    // small block (the gravity coefficients beside larger inertia ones) lose its exact fit.
    c.cost_cap = best.cost / P.cost_scale * (1 + 1e-6) + 1e-30;
    std::vector<EqualityData> eq;
    for (const auto &poly : P.equalities) eq.push_back({&c, &poly});
    nlopt_opt opt = make(NLOPT_LD_SLSQP, P);
    nlopt_set_min_objective(opt, distance, &c);
    add_constraints(opt, c, eq, P.tolerance);
    nlopt_add_inequality_constraint(opt, cost_cap_constraint, &c, 0.0);
    nlopt_set_maxeval(opt, P.local_maxeval);
    nlopt_set_ftol_rel(opt, 1e-14);
    std::vector<double> x = c.unit(best.p);
    double value = 0;
    nlopt_optimize(opt, x.data(), &value);
    nlopt_destroy(opt);
    Outcome out;
    out.p = c.full(x.data());
    out.cost = fit_cost(P, out.p, nullptr);
    out.violation = violation(P, out.p);
    if (out.violation <= P.tolerance && out.cost / P.cost_scale <= c.cost_cap * (1 + 1e-9)) return out;
    return best;
}

// The two-stage procedure fixes this stage's parameters in the next one, so among the parameters
// with this stage's fitted coefficients (infinitely many: 12 gravity coefficients, 23 parameters
// on the LWR) it keeps those that fit the next stage's targets best, rather than an arbitrary one
// (the next stage's cost depended on that pick: 1e-2 instead of 1e-10 on the LWR). The next stage
// then frees what this one does not determine and refits it.
Outcome hand_off(const Problem &P, const StandardBarrier &fitted, const Outcome &fit) {
    StandardBarrier next(P, P.next_blocks);
    if (!next.usable() || !fitted.usable()) return prefer_reference(P, fit);
    next.restrict_to(fitted, fit.p);
    if (!next.usable()) return prefer_reference(P, fit);
    Outcome out;
    out.p = next.solve(fit.p, P.local_maxeval);
    out.cost = fit_cost(P, out.p, nullptr);
    out.violation = violation(P, out.p);
    // this stage's coefficients are unchanged but for rounding (a relative cost of ~1e-25)
    const double allowed = fit.cost * (1 + 1e-6) + 100 * kStopCost * P.cost_scale;
    if (out.violation <= P.tolerance && out.cost <= allowed) return out;
    return prefer_reference(P, fit);
}

// ==== closes the namespace; main() runs the restarts in threads and writes the Result ============
}  // namespace

int main(int argc, char **argv) {
    const bool echo = argc == 4 && std::string(argv[1]) == "--echo";
    if (argc == 4 && std::string(argv[1]) == "--echo-result") {  // the result's round-trip test
        try {
            write_result(argv[3], read_result(argv[2]));
        } catch (const std::exception &e) {
            std::cerr << argv[2] << ": " << e.what() << '\n';
            return 2;
        }
        return 0;
    }
    if (argc != 3 && !echo) {
        std::cerr << "usage: " << argv[0] << " [--echo | --echo-result] PROBLEM_FILE RESULT_FILE\n";
        return 2;
    }
    Problem P;
    try {
        P = read_problem(argv[argc - 2]);
    } catch (const std::exception &e) {
        std::cerr << argv[argc - 2] << ": " << e.what() << '\n';
        return 2;
    }
    if (echo) {  // write the problem back as read: the protocol's round-trip test
        write_problem(argv[3], P);
        return 0;
    }
    const int threads = P.threads > 0 ? P.threads : std::max(1u, std::thread::hardware_concurrency());
    const StandardBarrier barrier(P, P.blocks);
    std::vector<Outcome> outcomes(P.restarts);
    std::atomic<int> next{0}, done{0};
    auto worker = [&]() {
        for (int k = next++; k < P.restarts; k = next++) {
            outcomes[k] = run_restart(P, barrier, k);
            const int finished = ++done;
            // One write per line: concurrent `<<` chains on std::cerr interleave between threads.
            const std::string line = "progress " + std::to_string(finished) + ' ' + std::to_string(P.restarts) + '\n';
            std::fputs(line.c_str(), stderr);
        }
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (auto &t : pool) t.join();

    int best = -1, consistent = 0;
    for (int k = 0; k < P.restarts; ++k) {
        if (outcomes[k].violation > P.tolerance) continue;
        ++consistent;
        if (best < 0 || outcomes[k].cost < outcomes[best].cost) best = k;
    }
    Result R;
    R.restarts = P.restarts;
    R.consistent = consistent;
    R.restart_costs.resize(P.restarts);
    R.restart_violations.resize(P.restarts);
    for (int k = 0; k < P.restarts; ++k) {
        R.restart_costs[k] = outcomes[k].cost;
        R.restart_violations[k] = outcomes[k].violation;
    }
    if (best < 0) {  // report the least violating point, so the caller can name what conflicts
        int closest = 0;
        for (int k = 1; k < P.restarts; ++k)
            if (outcomes[k].violation < outcomes[closest].violation) closest = k;
        R.status = "infeasible";
        R.parameters = outcomes[closest].p;
        write_result(argv[2], R);
        return 0;
    }
    const Outcome fit = outcomes[best];
    const Outcome chosen = !P.nearest ? fit : P.next_blocks.empty() ? prefer_reference(P, fit) : hand_off(P, barrier, fit);
    R.status = "ok";
    R.best_restart = best;
    R.fit_cost = fit.cost;
    R.cost = chosen.cost;
    R.violation = chosen.violation;
    R.parameters = chosen.p;
    for (const Block &b : P.blocks) {
        Eigen::VectorXd pi(b.kind->rank);
        b.kind->pi(chosen.p.data(), pi.data());
        R.residuals.push_back({b.kind->name, b.W * pi - b.v});
    }
    R.lambda_min.resize(kLinks);
    for (int link = 0; link < kLinks; ++link)
        R.lambda_min[link] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(density_matrix(chosen.p, link),
                                                                            Eigen::EigenvaluesOnly).eigenvalues()[0];
    write_result(argv[2], R);
    return 0;
}
