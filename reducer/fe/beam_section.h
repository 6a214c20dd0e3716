// Cross-section properties of a beam from a named shape or explicit values.
#pragma once

#include "formats/part_file.h"

namespace femb {

/// Section properties in the beam's local axes (x along the beam, y and z across).
struct SectionProperties {
  double A = 0.0;   ///< area [length^2]
  double Iy = 0.0;  ///< int z^2 dA: bending in the x-z plane [length^4]
  double Iz = 0.0;  ///< int y^2 dA: bending in the x-y plane [length^4]
  double J = 0.0;   ///< torsion constant [length^4]
  double Ip = 0.0;  ///< polar moment Iy + Iz, for rotary inertia about x [length^4]
  double ky = 0.0;  ///< shear factor for shear along y (shear area ky A); 0: rigid in shear
  double kz = 0.0;  ///< shear factor for shear along z
};

/// circle (diameter d): A = pi d^2/4, I = pi d^4/64, J = Ip = 2I, k = 6(1+nu)/(7+6nu) (Cowper 1966).
/// tube (outer radius R, wall t): I = pi (R^4 - r^4)/4, Cowper's hollow-circle k with m = r/R.
/// rectangle (width b along y, height h along z): Iz = h b^3/12, Iy = b h^3/12,
///   J = a c^3 (1/3 - 0.21 (c/a)(1 - c^4/(12 a^4))) with a >= c the sides (Roark),
///   k = 10(1+nu)/(12+11nu) (Cowper). general: as given; k defaults to 0 (Euler-Bernoulli).
SectionProperties ComputeSectionProperties(const BeamSectionSpec& spec, double nu);

}  // namespace femb
