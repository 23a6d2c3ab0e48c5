"""Exact cos and sin of a fixed angle (a DH twist, a URDF rpy angle), as the derivation needs them.

At multiples of pi/12 SymPy's closed forms: 0, +-1, +-1/2, sqrt(2)/2, sqrt(3)/2, (sqrt(6) +-
sqrt(2))/4, all in Q(sqrt 2, sqrt 3), which the exact rank evaluates (reduction/exact.py); at
multiples of pi/2 these are the values DH tables have always produced, so their output is
unchanged. Any other angle (0.3 rad, pi/5, a URDF's unsnapped 1.5708) becomes the rational
point of the unit circle ((1 - t^2)/(1 + t^2), 2t/(1 + t^2)) with t a rational within 1e-16
of tan(angle/2): cos^2 + sin^2 = 1 holds exactly, so every rotation built from it stays
orthogonal and the rank is that of the arm with this angle (off by < 1e-15 rad).
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import sympy as sp

CLOSED_FORM_DENOMINATOR = 12  # multiples of pi/12
_T_DENOMINATOR = 10**8  # |t - tan(angle/2)| < 1e-16: below double precision


def cos_sin(angle) -> tuple[sp.Expr, sp.Expr]:
    angle = sp.sympify(angle)
    ratio = sp.nsimplify(angle / sp.pi) if angle.has(sp.pi) else None
    if angle == 0 or (ratio is not None and ratio.is_Rational and CLOSED_FORM_DENOMINATOR % ratio.q == 0):
        return sp.cos(angle), sp.sin(angle)
    return rational_circle_point(angle)


def rational_circle_point(angle) -> tuple[sp.Rational, sp.Rational]:
    with mpmath.workdps(40):
        value = mpmath.mpf(sp.N(angle, 45)._mpf_) if not isinstance(angle, (int, float)) else mpmath.mpf(angle)
        value = mpmath.fmod(value, 2 * mpmath.pi)  # into (-2 pi, 2 pi), then into [-pi, pi]
        value = value - 2 * mpmath.pi if value > mpmath.pi else value + 2 * mpmath.pi if value < -mpmath.pi else value
        turned = abs(value) > mpmath.pi / 2  # then the angle minus pi: |half angle| <= pi/4, so |t| <= 1
        if turned:
            value = value - mpmath.sign(value) * mpmath.pi
        t = Fraction(mpmath.nstr(mpmath.tan(value / 2), 35, min_fixed=-50, max_fixed=50)).limit_denominator(_T_DENOMINATOR)
    t = sp.Rational(t.numerator, t.denominator)
    c, s = (1 - t**2) / (1 + t**2), 2 * t / (1 + t**2)
    return (-c, -s) if turned else (c, s)
