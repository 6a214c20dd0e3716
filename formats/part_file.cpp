#include "formats/part_file.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "formats/input_error.h"
#include "formats/yaml_reader.h"

namespace femb {
namespace {

std::string Fnv1a64(const std::string& text) {
  unsigned long long h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", h);
  return buffer;
}

MaterialSpec ParseMaterial(const YamlValue& value) {
  YamlMap m = value.Map();
  MaterialSpec material;
  material.E = m.Required("E").PositiveNumber();
  YamlValue nu = m.Required("nu");
  material.nu = nu.Number();
  if (!(material.nu > -1.0 && material.nu < 0.5)) {
    nu.Fail("Poisson's ratio must be in (-1, 0.5), got " + std::to_string(material.nu));
  }
  material.rho = m.Required("rho").PositiveNumber();
  m.CheckNoUnknownKeys();
  return material;
}

BeamSectionSpec ParseSection(const YamlValue& value) {
  YamlMap m = value.Map();
  BeamSectionSpec s;
  s.where = value.Where();
  s.shape = m.Required("shape").Kind<SectionShape>("section shape");
  if (s.shape == SectionShape::kCircle) {
    s.diameter = m.Required("diameter").PositiveNumber();
  } else if (s.shape == SectionShape::kTube) {
    s.outer_radius = m.Required("outer_radius").PositiveNumber();
    YamlValue wall = m.Required("wall");
    s.wall = wall.PositiveNumber();
    if (s.wall > s.outer_radius) {
      wall.Fail("tube wall " + std::to_string(s.wall) + " is thicker than the outer radius " +
                std::to_string(s.outer_radius));
    }
  } else if (s.shape == SectionShape::kRectangle) {
    s.width = m.Required("width").PositiveNumber();
    s.height = m.Required("height").PositiveNumber();
  } else {  // kGeneral
    s.A = m.Required("A").PositiveNumber();
    s.Iy = m.Required("Iy").PositiveNumber();
    s.Iz = m.Required("Iz").PositiveNumber();
    s.J = m.Required("J").PositiveNumber();
    if (auto v = m.Optional("Ip")) s.Ip = v->PositiveNumber();
  }
  // Shear factors override the shape's own (Cowper) values; a general section without them
  // is rigid in shear.
  if (auto v = m.Optional("ky")) s.ky = v->PositiveNumber();
  if (auto v = m.Optional("kz")) s.kz = v->PositiveNumber();
  m.CheckNoUnknownKeys();
  return s;
}

void ParseBeam(const YamlValue& value, PartSpec& part) {
  YamlMap m = value.Map();
  BeamSpec& beam = part.beam;
  std::map<std::string, int> index;
  YamlValue points = m.Required("points");
  for (const auto& [name, coords] : points.Map().Entries()) {
    index[name] = int(beam.points.size());
    beam.point_names.push_back(name);
    beam.points.push_back(coords.Vector3());
  }
  if (beam.points.size() < 2) points.Fail("a beam needs at least 2 points");
  YamlValue segments = m.Required("segments");
  for (const YamlValue& item : segments.List()) {
    YamlMap s = item.Map();
    BeamSegmentSpec seg;
    seg.where = item.Where();
    for (auto [key, target] : {std::pair{"from", &seg.from}, std::pair{"to", &seg.to}}) {
      YamlValue v = s.Required(key);
      auto it = index.find(v.String());
      if (it == index.end()) v.Fail("point '" + v.String() + "' is not defined in beam.points");
      *target = it->second;
    }
    YamlValue elements = s.Required("elements");
    seg.elements = int(elements.Integer());
    if (seg.elements < 1) elements.Fail("a segment needs at least 1 element, got " + std::to_string(seg.elements));
    if ((beam.points[seg.to] - beam.points[seg.from]).norm() == 0.0) {
      item.Fail("zero-length element: points '" + beam.point_names[seg.from] + "' and '" + beam.point_names[seg.to] +
                "' coincide");
    }
    if (auto sec = s.Optional("section")) seg.section = ParseSection(*sec);
    s.CheckNoUnknownKeys();
    beam.segments.push_back(seg);
  }
  if (beam.segments.empty()) segments.Fail("a beam needs at least one segment");
  if (auto v = m.Optional("orientation")) {
    Eigen::Vector3d o = v->Vector3();
    if (o.norm() == 0.0) v->Fail("orientation vector must not be zero");
    beam.orientation = o;
  }
  if (auto v = m.Optional("theory")) {
    std::string theory = v->String();
    if (theory == "timoshenko")
      beam.shear_deformation = true;
    else if (theory == "euler_bernoulli")
      beam.shear_deformation = false;
    else
      v->Fail("unknown beam theory '" + theory + "' (known: timoshenko, euler_bernoulli)");
  }
  m.CheckNoUnknownKeys();
}

}  // namespace

namespace {

// Plausible ranges per unit system: densities from foams to tungsten, moduli from rubber to
// 1000 x steel (stand-ins for rigid parts), parts from 1 mm to 50 m. A value outside its system's range but inside
// another's is the signature of mixed units.
struct UnitRange {
  const char* system;
  double rho_lo, rho_hi, E_lo, E_hi, length_lo, length_hi;
  const char* rho_unit;
  const char* E_unit;
  const char* length_unit;
};
constexpr UnitRange kUnitRanges[] = {
    {"SI", 5.0, 3.0e4, 1.0e6, 1.0e15, 1.0e-3, 50.0, "kg/m^3", "Pa", "m"},
    {"mm-t-s", 5.0e-12, 3.0e-8, 1.0, 1.0e9, 1.0, 5.0e4, "t/mm^3", "MPa", "mm"},
    {"mm-kg-ms", 5.0e-9, 3.0e-5, 1.0e-3, 1.0e6, 1.0, 5.0e4, "kg/mm^3", "GPa", "mm"},
};

const UnitRange& RangeOf(const std::string& system) {
  for (const UnitRange& r : kUnitRanges)
    if (system == r.system) return r;
  return kUnitRanges[0];
}

// "it looks like mm-t-s" for the systems whose range holds `value` (member selects the range).
std::string LooksLike(double value, double UnitRange::*lo, double UnitRange::*hi, const std::string& declared) {
  std::string systems;
  for (const UnitRange& r : kUnitRanges) {
    if (declared != r.system && value >= r.*lo && value <= r.*hi)
      systems += (systems.empty() ? "" : " or ") + std::string(r.system);
  }
  return systems.empty() ? "" : "; it looks like " + systems + " (mixed units?)";
}

std::string Implausible(const char* what, double value, const std::string& system, const char* unit, double lo,
                        double hi, const std::string& looks_like) {
  char buffer[300];
  std::snprintf(buffer, sizeof buffer,
                "%s = %.4g is implausible for units %s (%s, expected %.3g .. %.3g)%s; fix the "
                "value or 'units', or set check_units: false",
                what, value, system.c_str(), unit, lo, hi, looks_like.c_str());
  return buffer;
}

void CheckMaterialUnits(const PartSpec& part, const YamlValue& material) {
  const UnitRange& r = RangeOf(part.units.system);
  YamlMap m = material.Map();
  const double rho = part.material.rho, E = part.material.E;
  if (rho < r.rho_lo || rho > r.rho_hi) {
    m.Required("rho").Fail(Implausible("rho", rho, part.units.system, r.rho_unit, r.rho_lo, r.rho_hi,
                                       LooksLike(rho, &UnitRange::rho_lo, &UnitRange::rho_hi, part.units.system)));
  }
  if (E < r.E_lo || E > r.E_hi) {
    m.Required("E").Fail(Implausible("E", E, part.units.system, r.E_unit, r.E_lo, r.E_hi,
                                     LooksLike(E, &UnitRange::E_lo, &UnitRange::E_hi, part.units.system)));
  }
}

// interfaces[k].select: {cylinder: {point, axis, radius, [length]}, tolerance} (or sphere:
// {center, radius}, box: {min, max}, plane: {point, normal}).
NodeSelectionSpec ParseSelection(const YamlValue& value) {
  YamlMap m = value.Map();
  NodeSelectionSpec s;
  s.where = value.Where();
  if (auto t = m.Optional("tolerance")) s.tolerance = t->PositiveNumber();
  int shapes = 0;
  auto unit = [](const YamlValue& v) {
    const Eigen::Vector3d a = v.Vector3();
    if (!(a.norm() > 0)) v.Fail("must be a nonzero vector");
    return Eigen::Vector3d(a.normalized());
  };
  if (auto c = m.Optional("cylinder")) {
    ++shapes;
    YamlMap g = c->Map();
    s.shape = SelectionShape::kCylinder;
    s.point = g.Required("point").Vector3();
    s.axis = unit(g.Required("axis"));
    s.radius = g.Required("radius").PositiveNumber();
    if (auto l = g.Optional("length")) s.length = l->PositiveNumber();
    g.CheckNoUnknownKeys();
  }
  if (auto c = m.Optional("sphere")) {
    ++shapes;
    YamlMap g = c->Map();
    s.shape = SelectionShape::kSphere;
    s.point = g.Required("center").Vector3();
    s.radius = g.Required("radius").PositiveNumber();
    g.CheckNoUnknownKeys();
  }
  if (auto c = m.Optional("box")) {
    ++shapes;
    YamlMap g = c->Map();
    s.shape = SelectionShape::kBox;
    s.point = g.Required("min").Vector3();
    YamlValue max = g.Required("max");
    s.axis = max.Vector3();
    if (!((s.axis - s.point).minCoeff() >= 0)) max.Fail("every coordinate of max must be at least that of min");
    g.CheckNoUnknownKeys();
  }
  if (auto c = m.Optional("plane")) {
    ++shapes;
    YamlMap g = c->Map();
    s.shape = SelectionShape::kPlane;
    s.point = g.Required("point").Vector3();
    s.axis = unit(g.Required("normal"));
    g.CheckNoUnknownKeys();
  }
  if (shapes != 1) value.Fail("give exactly one of cylinder, sphere, box, plane");
  m.CheckNoUnknownKeys();
  return s;
}

}  // namespace

void CheckPartSize(const PartSpec& part, double diagonal, const std::string& where) {
  if (!part.check_units) return;
  const UnitRange& r = RangeOf(part.units.system);
  if (diagonal < r.length_lo || diagonal > r.length_hi) {
    throw InputError(where + ": " +
                     Implausible("part size (bounding-box diagonal)", diagonal, part.units.system, r.length_unit,
                                 r.length_lo, r.length_hi,
                                 LooksLike(diagonal, &UnitRange::length_lo, &UnitRange::length_hi, part.units.system)));
  }
}

Units UnitSystem(const std::string& name, const std::string& where) {
  Units u;
  u.system = name;
  if (name == "SI") return u;
  if (name == "mm-t-s") {
    u.length = "mm";
    u.mass = "t";
    u.time = "s";
    u.force = "N";
    u.stress = "MPa";
    return u;
  }
  if (name == "mm-kg-ms") {
    u.length = "mm";
    u.mass = "kg";
    u.time = "ms";
    u.force = "kN";
    u.stress = "GPa";
    return u;
  }
  throw InputError(where + ": unknown unit system '" + name + "' (known: SI, mm-t-s, mm-kg-ms)");
}

namespace {

// A file named in the part, resolved against the part file's folder; fails naming `file` when it
// does not exist.
std::string ResolvePath(const YamlValue& file, const std::string& what, const std::string& part_file) {
  std::filesystem::path f(file.String());
  if (f.is_relative()) f = std::filesystem::path(part_file).parent_path() / f;
  if (!std::filesystem::exists(f)) file.Fail(what + " '" + f.string() + "' not found");
  return f.string();
}

// The material: required for beams and solids; optional for imported parts, whose matrices carry
// it (given, it lets femb's own elements on the imported mesh's solid cells build the geometric
// stiffening).
void ParsePartMaterial(YamlMap& root, PartSpec& part) {
  if (part.type != PartType::kImported) {
    part.material = ParseMaterial(root.Required("material"));
    if (part.check_units) CheckMaterialUnits(part, root.Required("material"));
  } else if (auto material = root.Optional("material")) {
    part.material = ParseMaterial(*material);
    if (part.check_units) CheckMaterialUnits(part, *material);
  } else {
    part.has_material = false;
  }
}

// An imported part's files: the matrices carry the material; the geometry file gives the node
// coordinates (and ids).
void ParseImported(YamlMap& root, PartSpec& part) {
  YamlValue geometry = root.Required("geometry");
  YamlMap g = geometry.Map();
  part.solid.where = geometry.Where();
  part.solid.file = ResolvePath(g.Required("file"), "geometry file", part.file);
  g.CheckNoUnknownKeys();
  YamlValue matrices = root.Required("matrices");
  YamlMap m = matrices.Map();
  MatricesSpec& x = part.matrices;
  x.where = matrices.Where();
  x.format = m.Required("format").OneOfKinds<MatrixFormat>();
  x.stiffness = ResolvePath(m.Required("stiffness"), "stiffness matrix file", part.file);
  x.mass = ResolvePath(m.Required("mass"), "mass matrix file", part.file);
  std::string extension = std::filesystem::path(part.solid.file).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".inp") x.deck = part.solid.file;
  const bool abaqus = x.format == MatrixFormat::kAbaqus || x.format == MatrixFormat::kAbaqusCoordinate;
  if (auto instance = m.Optional("instance")) {
    if (!abaqus || x.deck.empty())
      throw InputError(instance->Where() +
                       ": instance names an instance of an Abaqus deck: it needs format abaqus "
                       "(or abaqus_coordinate) and a geometry file .inp");
    x.instance = instance->String();
  }
  if (x.format == MatrixFormat::kAbaqusCoordinate && x.deck.empty()) {
    throw InputError(matrices.Where() +
                     ": format abaqus_coordinate numbers equations, not nodes: the geometry file "
                     "must be the Abaqus deck (.inp) the matrices were generated from");
  }
  if (!abaqus && x.format != MatrixFormat::kNastran) {
    x.dofs = ResolvePath(m.Required("dofs"),
                         x.format == MatrixFormat::kCalculix ? "DOF map (job.dof)"
                         : x.format == MatrixFormat::kAnsys  ? "DOF mapping file (HBMAT's Fname.mapping)"
                                                             : "DOF map (CSV: node, component)",
                         part.file);
  }
  m.CheckNoUnknownKeys();
}

// A beam part's section and beam line, with the part's size checked against its units.
void ParseBeamPart(YamlMap& root, PartSpec& part) {
  part.beam.section = ParseSection(root.Required("section"));
  ParseBeam(root.Required("beam"), part);
  Eigen::Vector3d lo = part.beam.points[0], hi = lo;
  for (const auto& p : part.beam.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  YamlValue beam = root.Required("beam");
  CheckPartSize(part, (hi - lo).norm(), beam.Where() + ".points");
}

// A solid part's geometry (a built-in shape or a CAD/mesh file) and mesh settings.
void ParseSolidPart(YamlMap& root, PartSpec& part) {
  YamlValue geometry = root.Required("geometry");
  YamlMap g = geometry.Map();
  part.solid.where = geometry.Where();
  if (auto shape = g.Optional("shape")) {
    part.solid.shape = shape->OneOfKinds<SolidShape>();
    if (part.solid.shape == SolidShape::kBox || part.solid.shape == SolidShape::kPlate) {
      YamlValue size = g.Required("size");
      part.solid.size = size.Vector3();
      if (!(part.solid.size.minCoeff() > 0)) size.Fail("edge lengths must be positive");
      CheckPartSize(part, part.solid.size.norm(), size.Where());
    } else {
      part.solid.radius = g.Required("radius").PositiveNumber();
      YamlValue length = g.Required("length");
      part.solid.length = length.PositiveNumber();
      if (part.solid.shape == SolidShape::kTube) {
        YamlValue inner = g.Required("inner_radius");
        part.solid.inner_radius = inner.PositiveNumber();
        if (part.solid.inner_radius >= part.solid.radius) inner.Fail("inner_radius must be smaller than radius");
      }
      CheckPartSize(part, std::hypot(2 * part.solid.radius, part.solid.length), length.Where());
    }
  } else {
    part.solid.file = ResolvePath(g.Required("file"), "geometry file", part.file);
  }
  g.CheckNoUnknownKeys();
  if (auto mesh = root.Optional("mesh")) {
    YamlMap m = mesh->Map();
    if (auto v = m.Optional("size")) part.solid.element_size = v->PositiveNumber();
    if (auto v = m.Optional("order")) {
      part.solid.order = int(v->Integer());
      if (part.solid.order != 1 && part.solid.order != 2) v->Fail("element order must be 1 or 2");
    }
    if (auto v = m.Optional("max_elements")) part.solid.max_elements = long(v->PositiveNumber());
    if (auto v = m.Optional("elements")) {
      part.solid.hexahedra = v->OneOf({"tetrahedra", "hexahedra"}) == "hexahedra";
      if (part.solid.hexahedra && part.solid.shape != SolidShape::kBox && part.solid.shape != SolidShape::kPlate) {
        v->Fail("hexahedra are available for the built-in box and plate only");
      }
    }
    m.CheckNoUnknownKeys();
  }
}

// One item of `interfaces`: a beam point, or a node set of a solid (group or selection) with its
// coupling.
InterfaceSpec ParseInterface(const YamlValue& item, const PartSpec& part) {
  YamlMap m = item.Map();
  InterfaceSpec spec;
  spec.where = item.Where();
  spec.name = m.Required("name").String();
  if (part.type == PartType::kBeam) {
    YamlValue point = m.Optional("point").value_or(m.Required("name"));
    const std::string point_name = point.String();
    for (size_t i = 0; i < part.beam.point_names.size(); ++i) {
      if (part.beam.point_names[i] == point_name) spec.point = int(i);
    }
    if (spec.point < 0) point.Fail("interface point '" + point_name + "' not found in beam.points");
    for (const auto& other : part.interfaces) {
      if (other.point == spec.point) item.Fail("point '" + point_name + "' is already interface '" + other.name + "'");
    }
  } else {
    auto group = m.Optional("group");
    auto select = m.Optional("select");
    if (group.has_value() == select.has_value()) {
      item.Fail("interface '" + spec.name +
                "': give either 'group' (a named node set of the mesh) or 'select' "
                "(nodes picked by geometry: cylinder, sphere, box or plane)");
    }
    if (group) spec.group = group->String();
    if (select) spec.select = ParseSelection(*select);
    if (auto c = m.Optional("coupling")) spec.coupling = c->Kind<Coupling>("coupling");
    if (auto p = m.Optional("point")) spec.location = p->Vector3();
  }
  for (const auto& other : part.interfaces) {
    if (other.name == spec.name) item.Fail("interface name '" + spec.name + "' used twice");
  }
  m.CheckNoUnknownKeys();
  return spec;
}

// reduction.floating_frame: center_of_mass, mean_axes, cardona or interface:<name>.
void ParseFloatingFrame(const YamlValue& v, PartSpec& part) {
  part.reduction.where_floating_frame = v.Where();
  const std::string f = v.String();
  if (f.rfind("interface:", 0) == 0) {
    const std::string iname = f.substr(10);
    bool found = false;
    for (const auto& i : part.interfaces) found |= (i.name == iname);
    if (!found) v.Fail("floating frame interface '" + iname + "' is not one of the part's interfaces");
    part.reduction.floating_frame = FloatingFrameType::kInterface;
    part.reduction.floating_frame_interface = iname;
  } else if (std::optional<FloatingFrameType> type = KindOf<FloatingFrameType>(f);
             type && *type != FloatingFrameType::kInterface) {
    part.reduction.floating_frame = *type;
  } else {
    v.Fail("unknown floating frame '" + f + "' (known: center_of_mass, mean_axes, interface:<name>, cardona)");
  }
}

// reduction.modal_derivatives: true/false, or which pairs and the tolerance.
void ParseModalDerivatives(const YamlValue& v, PartSpec& part) {
  ModalDerivativeSpec& d = part.reduction.modal_derivatives;
  d.where = v.Where();
  if (v.IsScalar()) {
    d.enabled = v.Bool();
  } else {
    d.enabled = true;
    YamlMap dm = v.Map();
    if (auto o = dm.Optional("of")) d.of = o->OneOfKinds<DerivativePairs>("(which coordinates are paired)");
    if (auto t = dm.Optional("tolerance")) d.tolerance = t->PositiveNumber();
    if (auto p = dm.Optional("pairs")) {
      for (const YamlValue& item : p->List()) {
        const std::vector<YamlValue> ij = item.List();
        if (ij.size() != 2) item.Fail("a pair is two reduced coordinate indices, e.g. [1, 7]");
        d.pairs.emplace_back(int(ij[0].NonNegativeInteger()), int(ij[1].NonNegativeInteger()));
      }
    }
    dm.CheckNoUnknownKeys();
  }
  if (d.enabled && part.type == PartType::kImported) {
    v.Fail("modal derivatives need femb's own elements (the nonlinear strain); imported matrices do not have them");
  }
}

// `reduction`.
void ParseReduction(const YamlValue& r, PartSpec& part) {
  YamlMap m = r.Map();
  if (auto v = m.Optional("internal_modes")) part.reduction.internal_modes = int(v->NonNegativeInteger());
  if (auto v = m.Optional("method")) {
    part.reduction.method = v->OneOfKinds<ReductionMethod>();
    part.reduction.where_method = v->Where();
  }
  if (auto v = m.Optional("basis")) {
    YamlMap b = v->Map();
    part.reduction.where_basis = v->Where();
    part.reduction.basis_file = ResolvePath(b.Required("file"), "deformation shapes file", part.file);
    b.CheckNoUnknownKeys();
    if (part.reduction.method != ReductionMethod::kGeneral)
      v->Fail("a basis file is read with reduction.method: general only");
  } else if (part.reduction.method == ReductionMethod::kGeneral) {
    m.AsValue().Fail("reduction.method general needs reduction.basis: {file: shapes.mtx}");
  }
  if (auto v = m.Optional("floating_frame")) ParseFloatingFrame(*v, part);
  if (auto v = m.Optional("keep_mesh")) part.reduction.keep_mesh = v->Bool();
  if (auto v = m.Optional("stresses")) {
    part.reduction.stresses = v->Bool();
    if (*part.reduction.stresses && part.type == PartType::kImported && !part.has_material) {
      v->Fail(
          "stresses of imported matrices need the part's material: (femb's own elements on the imported mesh's "
          "solid cells recover them)");
    }
    part.reduction.where_stresses = v->Where();
    if (*part.reduction.stresses && part.reduction.keep_mesh == false) {
      v->Fail("reduction.stresses: true needs the mesh: keep_mesh is false (the stresses live on its nodes)");
    }
  }
  if (auto v = m.Optional("geometric_stiffening")) {
    part.reduction.geometric_stiffening = v->Bool();
    if (*part.reduction.geometric_stiffening && part.type == PartType::kImported && !part.has_material) {
      v->Fail(
          "geometric stiffening of imported matrices needs the part's material: (E, nu, rho; femb's own elements "
          "on the imported mesh's solid cells give the stress of each field)");
    }
  }
  if (auto v = m.Optional("full_modes")) {
    part.reduction.full_modes = int(v->NonNegativeInteger());
    part.reduction.full_modes_given = true;
  }
  if (auto v = m.Optional("memory_limit_gb")) part.reduction.memory_limit_gb = v->PositiveNumber();
  if (auto v = m.Optional("solver")) {
    part.reduction.solver = v->OneOfKinds<ReductionSolver>();
    part.reduction.where_solver = v->Where();
  }
  if (auto v = m.Optional("modal_derivatives")) ParseModalDerivatives(*v, part);
  m.CheckNoUnknownKeys();
  if (part.reduction.method != ReductionMethod::kCraigBampton &&
      (part.reduction.modal_derivatives.enabled || part.reduction.geometric_stiffening.value_or(false))) {
    throw InputError(part.reduction.where_method +
                     ": modal derivatives and geometric stiffening are built on the "
                     "Craig-Bampton basis: use reduction.method: craig_bampton with them");
  }
}

}  // namespace

PartSpec ParsePart(const std::string& text, const std::string& name, const std::vector<std::string>& overrides) {
  YamlDocument doc = YamlDocument::LoadString(text, name);
  std::string effective = text;
  for (const auto& o : overrides) {
    doc.Set(o);
    effective += "\n#--set " + o;
  }
  YamlMap root = doc.Root();
  PartSpec part;
  part.file = name;
  part.text_hash = Fnv1a64(effective);
  part.name = root.Required("name").String();
  part.type = root.Required("type").Kind<PartType>("part type");
  if (auto u = root.Optional("units")) part.units = UnitSystem(u->String(), u->Where());
  if (auto v = root.Optional("check_units")) part.check_units = v->Bool();
  ParsePartMaterial(root, part);
  if (part.type == PartType::kImported) {
    ParseImported(root, part);
  } else if (part.type == PartType::kBeam) {
    ParseBeamPart(root, part);
  } else {
    ParseSolidPart(root, part);
  }
  auto interfaces = root.Optional("interfaces");
  if (!interfaces || interfaces->List().empty()) {
    throw InputError(name +
                     ": no interface defined: list at least one under 'interfaces' "
                     "(a superelement couples to the world only through interface nodes)");
  }
  for (const YamlValue& item : interfaces->List()) part.interfaces.push_back(ParseInterface(item, part));
  if (auto r = root.Optional("reduction")) ParseReduction(*r, part);
  if (part.reduction.where_method.empty()) part.reduction.where_method = name;
  if (part.reduction.where_floating_frame.empty()) part.reduction.where_floating_frame = name;
  root.CheckNoUnknownKeys();
  return part;
}

PartSpec ReadPartFile(const std::string& path, const std::vector<std::string>& overrides) {
  return ParsePart(ReadTextFile(path, "part file"), path, overrides);
}

}  // namespace femb
