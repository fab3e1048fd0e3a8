#pragma once
// Real roots of polynomials of degree <= 4 in closed form, made robust (see docs/solver.md).
// Coefficients are in ascending order: c[0] + c[1] x + c[2] x^2 + ...
// Roots come back sorted ascending; each is polished by Newton steps on the input polynomial.
// Leading coefficients that are zero, or negligible against the others, lower the degree
// (the dropped roots are at "infinity" for ray tracing purposes).

namespace lat {

int solve_quadratic(const double c[3], double roots[2]);
int solve_cubic(const double c[4], double roots[3]);
int solve_quartic(const double c[5], double roots[4]);

}  // namespace lat
