#include "test_util.h"

#include <gtest/gtest.h>

#include <sstream>

#include "reducer/reduce_part.h"

namespace femb::test {

std::string StraightBeamYaml(double L, int elements, const std::string& section,
                             const std::string& material, const std::string& interfaces,
                             const std::string& extra) {
  std::ostringstream s;
  s.precision(17);
  s << "name: test_beam\ntype: beam\nmaterial: " << material << "\nsection: " << section
    << "\nbeam:\n  points:\n    A: [0, 0, 0]\n    B: [" << L << ", 0, 0]\n"
    << "  segments:\n    - {from: A, to: B, elements: " << elements << "}\n"
    << "interfaces: " << interfaces << "\n"
    << extra;
  return s.str();
}

Superelement Reduce(const std::string& yaml, const std::vector<std::string>& overrides) {
  PartSpec part = ParsePart(yaml, "test.yaml", overrides);
  ReduceResult r = ReducePart(part, nullptr);
  EXPECT_TRUE(r.ok) << r.message;
  return r.superelement;
}

}  // namespace femb::test
