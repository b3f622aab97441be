#pragma once
// Pressure-driven flow along x through a straight channel (viscosity 1, mean velocity V): the
// undisturbed flow of a channel scene and the oracle of its empty-channel tests (docs/channel.md §2).
//   tube of radius R:  u_x = 2V (1 − r²/R²),  dp/dx = −8V/R²,  wall shear stress 4V/R;
//   square duct |y|, |z| ≤ W, G = −dp/dx, s = |y|/W, t = |z|/W (Boussinesq's series, e.g. White,
//   Viscous Fluid Flow, §3-3.3, with its algebraic part summed in closed form,
//   Σ_{n odd} (−1)^((n−1)/2) cos(nπs/2)/n³ = π³(1 − s²)/32):
//     u_x = G W² [ (1 − s²)/2 − (16/π³) Σ_{n odd} (−1)^((n−1)/2) n⁻³ cos(a_n s) cosh(a_n t)/cosh(a_n) ],  a_n = nπ/2,
//     V = (G W²/3) [1 − (192/π⁵) Σ_{n odd} tanh(a_n)/n⁵],
//     wall shear stress on z = ±W: G W [1 − (8/π²) Σ_{n odd} n⁻² cosh(a_n s)/cosh(a_n)].
// The series decay as exp(−a_n(1 − t)); the velocity is summed with the cosh in the smaller of
// |y|, |z| (the square's symmetry), so only points near a corner take many terms.
namespace capsflow {

double tube_poiseuille_velocity(double r, double R, double V);
double tube_poiseuille_pressure_gradient(double R, double V);  // dp/dx, negative for V > 0
double tube_poiseuille_wall_shear(double R, double V);         // 4V/R

double duct_poiseuille_velocity(double y, double z, double W, double V);
double duct_poiseuille_pressure_gradient(double W, double V);  // dp/dx
// The wall shear stress −∂u_x/∂n on the side z = W (or any side, by symmetry) at the position y
// along it: zero at the corners, largest at the middle.
double duct_poiseuille_wall_shear(double y, double W, double V);

}  // namespace capsflow
