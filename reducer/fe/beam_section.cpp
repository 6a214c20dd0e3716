#include "reducer/fe/beam_section.h"

#include <algorithm>
#include <cmath>

namespace femb {

SectionProperties ComputeSectionProperties(const BeamSectionSpec& s, double nu) {
  SectionProperties p;
  if (s.shape == SectionShape::kCircle) {
    const double r = 0.5 * s.diameter;
    p.A = M_PI * r * r;
    p.Iy = p.Iz = M_PI * std::pow(r, 4) / 4.0;
    p.J = p.Ip = 2.0 * p.Iy;
    p.ky = p.kz = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
  } else if (s.shape == SectionShape::kTube) {
    const double R = s.outer_radius, r = s.outer_radius - s.wall;
    p.A = M_PI * (R * R - r * r);
    p.Iy = p.Iz = M_PI * (std::pow(R, 4) - std::pow(r, 4)) / 4.0;
    p.J = p.Ip = 2.0 * p.Iy;
    const double m = r / R, m2 = (1 + m * m) * (1 + m * m);
    p.ky = p.kz = 6.0 * (1.0 + nu) * m2 / ((7.0 + 6.0 * nu) * m2 + (20.0 + 12.0 * nu) * m * m);
  } else if (s.shape == SectionShape::kRectangle) {
    const double b = s.width, h = s.height;
    p.A = b * h;
    p.Iz = h * b * b * b / 12.0;
    p.Iy = b * h * h * h / 12.0;
    p.Ip = p.Iy + p.Iz;
    const double a = std::max(b, h), c = std::min(b, h);
    p.J = a * c * c * c * (1.0 / 3.0 - 0.21 * (c / a) * (1.0 - std::pow(c / a, 4) / 12.0));
    p.ky = p.kz = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
  } else {  // general
    p.A = s.A;
    p.Iy = s.Iy;
    p.Iz = s.Iz;
    p.J = s.J;
    p.Ip = s.Ip > 0.0 ? s.Ip : s.Iy + s.Iz;
  }
  if (s.ky > 0.0) p.ky = s.ky;
  if (s.kz > 0.0) p.kz = s.kz;
  return p;
}

}  // namespace femb
