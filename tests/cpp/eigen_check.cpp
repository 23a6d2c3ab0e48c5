// Drives generated/lwr/lwr.hpp for tests/test_eigen_header.py: reads p and states on stdin,
// prints every wrapper's result ("name v1 v2 ..."), which the test compares with the C
// functions called through cffi and with the numpy Lagrangian.
// Arguments are passed in each form the header promises to take without a copy: fixed-size
// matrices, Maps over plain arrays (inputs and outputs) and column blocks.
#include <cstdio>

#include "lwr.hpp"

template <typename Derived>
static void print(const char *name, const Eigen::MatrixBase<Derived> &x)
{
    std::printf("%s", name);
    const double *data = x.derived().data();  // dense, in the C layout (row-major matrices)
    for (Eigen::Index k = 0; k < x.size(); ++k) std::printf(" %.17g", data[k]);
    std::printf("\n");
}

static bool read(double *to, int n)
{
    for (int k = 0; k < n; ++k)
        if (std::scanf("%lf", &to[k]) != 1) return false;
    return true;
}

int main()
{
    lwr::Parameters p;
    if (!read(p.data(), LWR_N_PARAMETERS)) return 2;
    const lwr::Parameters s = lwr::standard_from_dynamic(p);
    print("s", s);
    print("pi_gravity", lwr::pi_gravity(p));
    print("pi_inertia", lwr::pi_inertia(p));
    lwr::PiFull pi;
    lwr::pi_full(p, pi);
    print("pi_full", pi);
    print("pi_full_jacobian", lwr::pi_full_jacobian(p));

    double state[3 * LWR_DOF];
    while (read(state, 3 * LWR_DOF)) {
        Eigen::Map<const lwr::Joints> q(state), qd(state + LWR_DOF), qdd(state + 2 * LWR_DOF);

        double tau_array[LWR_DOF] = {0};
        lwr::rnea(q, qd, qdd, s, Eigen::Map<lwr::Joints>(tau_array));  // written in place
        print("tau_map", Eigen::Map<const lwr::Joints>(tau_array));

        Eigen::Matrix<double, LWR_DOF, 3> columns;  // column-major: each column is contiguous
        columns << q, qd, qdd;
        print("tau_block", lwr::rnea(columns.col(0), columns.col(1), columns.col(2), s));

        print("g", lwr::gravity(q, s));
        lwr::MassMatrix M;
        lwr::mass_matrix(q, s, M);
        print("M", M);
        print("Y_gravity", lwr::regressor_gravity(q));
        print("Y_inertia", lwr::regressor_inertia(q));
        const lwr::Regressor Y = lwr::regressor(q, qd, qdd);
        print("Y", Y);
        const lwr::Joints Y_pi = Y * pi;
        print("Y_pi", Y_pi);

        print("flange_pose", lwr::flange_pose(q));
        print("link_poses", lwr::link_poses(q));
        print("jacobian", lwr::jacobian(q));
        print("link_jacobians", lwr::link_jacobians(q));
        print("jacobian_dot_qd", lwr::jacobian_dot_qd(q, qd));
        lwr::Joints g_control, c_control;  // several outputs: the form that writes into arguments
        lwr::MassMatrix M_control;
        lwr::control(q, qd, s, g_control, M_control, c_control);
        print("control_g", g_control);
        print("control_M", M_control);
        print("control_c", c_control);
        lwr::Jacobian J;
        lwr::Twist jdot_qd;
        lwr::control_with_jacobian(q, qd, s, g_control, M_control, c_control, J, jdot_qd);
        print("control_J", J);
        print("control_jdot_qd", jdot_qd);
    }
    return 0;
}
