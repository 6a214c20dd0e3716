#include "formats/scene_file.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include "formats/input_error.h"
#include "formats/yaml_reader.h"

namespace femb {

double TimeFunctionSpec::Evaluate(double t) const {
  switch (type) {
    case TimeFunctionType::kLinear:
      return value * t;
    case TimeFunctionType::kConstant:
      return value;
    case TimeFunctionType::kRamp:
      if (t <= t_start) return 0.0;
      if (t >= t_end) return value;
      return value * (t - t_start) / (t_end - t_start);
    case TimeFunctionType::kStep:
      return t >= t_start ? value : 0.0;
    case TimeFunctionType::kPulse:
      return (t >= t_start && t < t_end) ? value : 0.0;
    case TimeFunctionType::kSine:
      return offset + amplitude * std::sin(2 * M_PI * frequency * t + phase);
    case TimeFunctionType::kSpinUp: {
      // theta = (w/Ts)(t^2/2 + (Ts/2pi)^2 (cos(2 pi t/Ts) - 1)) for t < Ts, then w (t - Ts/2).
      const double Ts = t_end, w = value, c = Ts / (2 * M_PI);
      if (t >= Ts) return w * (t - 0.5 * Ts);
      return w / Ts * (0.5 * t * t + c * c * (std::cos(t / c) - 1));
    }
    case TimeFunctionType::kTable: {
      if (t <= table.front().first) return table.front().second;
      if (t >= table.back().first) return table.back().second;
      auto it = std::upper_bound(table.begin(), table.end(), t, [](double v, const auto& p) { return v < p.first; });
      const auto& b = *it;
      const auto& a = *(it - 1);
      return a.second + (b.second - a.second) * (t - a.first) / (b.first - a.first);
    }
  }
  return 0.0;
}

std::vector<double> TimeFunctionSpec::Breakpoints() const {
  switch (type) {
    case TimeFunctionType::kRamp:
    case TimeFunctionType::kPulse:
      return {t_start, t_end};
    case TimeFunctionType::kStep:
      return {t_start};
    case TimeFunctionType::kSpinUp:
      return {t_end};
    case TimeFunctionType::kTable: {
      std::vector<double> out;
      for (const auto& p : table) out.push_back(p.first);
      return out;
    }
    default:
      return {};  // linear, constant, sine: smooth
  }
}

double TimeFunctionSpec::Rate(double t) const {
  switch (type) {
    case TimeFunctionType::kLinear:
      return value;
    case TimeFunctionType::kRamp:
      return (t >= t_start && t < t_end) ? value / (t_end - t_start) : 0.0;
    case TimeFunctionType::kSine:
      return amplitude * 2 * M_PI * frequency * std::cos(2 * M_PI * frequency * t + phase);
    case TimeFunctionType::kSpinUp: {
      const double Ts = t_end, w = value, c = Ts / (2 * M_PI);
      return t >= Ts ? w : w / Ts * (t - c * std::sin(t / c));
    }
    case TimeFunctionType::kTable:
      for (size_t i = 1; i < table.size(); ++i) {
        if (t >= table[i - 1].first && t < table[i].first) {
          return (table[i].second - table[i - 1].second) / (table[i].first - table[i - 1].first);
        }
      }
      return 0.0;  // outside its range
    default:
      return 0.0;  // constant, step, pulse
  }
}

double TimeFunctionSpec::Acceleration(double t) const {
  if (type == TimeFunctionType::kSine) {
    const double w = 2 * M_PI * frequency;
    return -amplitude * w * w * std::sin(w * t + phase);
  }
  if (type == TimeFunctionType::kSpinUp) {
    const double Ts = t_end, w = value, c = Ts / (2 * M_PI);
    return t >= Ts ? 0.0 : w / Ts * (1 - std::cos(t / c));
  }
  return 0.0;
}

namespace {

TimeFunctionSpec ParseFunction(const YamlValue& value) {
  YamlMap m = value.Map();
  TimeFunctionSpec f;
  f.type = m.Required("type").Kind<TimeFunctionType>("time function type");
  if (f.type == TimeFunctionType::kConstant) {
    f.value = m.Required("value").Number();
  } else if (f.type == TimeFunctionType::kRamp || f.type == TimeFunctionType::kPulse) {
    f.value = m.Required("value").Number();
    f.t_start = m.Required("t_start").Number();
    YamlValue t_end = m.Required("t_end");
    f.t_end = t_end.Number();
    if (!(f.t_end > f.t_start)) t_end.Fail("t_end must be after t_start");
  } else if (f.type == TimeFunctionType::kStep) {
    f.value = m.Required("value").Number();
    f.t_start = m.Required("t_start").Number();
  } else if (f.type == TimeFunctionType::kSine) {
    f.amplitude = m.Required("amplitude").Number();
    f.frequency = m.Required("frequency").Number();
    if (auto v = m.Optional("phase")) f.phase = v->Number();
    if (auto v = m.Optional("offset")) f.offset = v->Number();
  } else if (f.type == TimeFunctionType::kSpinUp) {
    f.value = m.Required("omega").Number();
    YamlValue ts = m.Required("t_spin");
    f.t_end = ts.PositiveNumber();
  } else if (f.type == TimeFunctionType::kTable) {
    YamlValue points = m.Required("points");
    for (const YamlValue& p : points.List()) {
      auto pair = p.List();
      if (pair.size() != 2) p.Fail("expected [t, value]");
      f.table.emplace_back(pair[0].Number(), pair[1].Number());
      if (f.table.size() > 1 && !(f.table.back().first > f.table[f.table.size() - 2].first)) {
        p.Fail("table times must increase");
      }
    }
    if (f.table.empty()) points.Fail("a table needs at least one point");
  } else {  // kLinear
    if (auto v = m.Optional("slope")) f.value = v->Number();
  }
  m.CheckNoUnknownKeys();
  return f;
}

// A name given to a node of some body, checked: the scene's node names.
class NodeNames {
 public:
  void Add(const std::string& name) { names_.insert(name); }
  bool Has(const std::string& name) const { return names_.count(name) > 0; }
  /// The node named by `v`; fails naming `v` when no body has it.
  std::string Check(const YamlValue& v) const {
    const std::string n = v.String();
    if (!Has(n)) v.Fail("node '" + n + "' is not a node of any body");
    return n;
  }

 private:
  std::set<std::string> names_;
};

// A rigid body's mass, centre of mass, inertia tensor and named points.
void ParseRigidBody(YamlMap& m, SceneBodySpec& b) {
  b.mass = m.Required("mass").PositiveNumber();
  if (auto v = m.Optional("center_of_mass")) b.center_of_mass = v->Vector3();
  YamlValue inertia = m.Required("inertia");
  std::vector<double> I;
  for (const YamlValue& v : inertia.List()) I.push_back(v.Number());
  if (I.size() != 3 && I.size() != 6) inertia.Fail("expected [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Iyz, Izx]");
  b.inertia.diagonal() << I[0], I[1], I[2];
  if (I.size() == 6) {
    b.inertia(0, 1) = b.inertia(1, 0) = I[3];
    b.inertia(1, 2) = b.inertia(2, 1) = I[4];
    b.inertia(2, 0) = b.inertia(0, 2) = I[5];
  }
  const Eigen::Vector3d p = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(b.inertia).eigenvalues();
  if (!(p[0] > 0) || p[0] + p[1] < p[2] * (1 - 1e-12)) {
    inertia.Fail("not a physical inertia tensor (principal moments must be positive and obey the triangle inequality)");
  }
  if (auto pts = m.Optional("points")) {
    for (const auto& [pname, value] : pts->Map().Entries()) b.points[pname] = value.Vector3();
  }
}

// A body's options (the formulation's choices; scene_file.h SceneBodySpec).
void ParseBodyOptions(const YamlValue& o, SceneBodySpec& b) {
  YamlMap om = o.Map();
  if (auto v = om.Optional("transformations")) b.approximated = v->OneOf({"exact", "approximated"}) == "approximated";
  if (auto v = om.Optional("tangent")) b.full_tangent = v->OneOf({"full", "K1"}) == "full";
  if (auto v = om.Optional("quadratic_velocity_terms")) b.quadratic_velocity_terms = v->Bool();
  if (auto v = om.Optional("internal_force")) {
    b.polynomial_force =
        v->OneOf({"polynomial", "linear"},
                 "(polynomial: the file's Green-Lagrange force when it has modal derivatives)") == "polynomial";
  }
  if (auto v = om.Optional("geometric_stiffening")) b.geometric_stiffening = v->Bool();
  if (auto v = om.Optional("inertia")) {
    b.exact_inertia = v->OneOf({"exact", "corotational"}, "(exact: the file's inertia invariants)") == "exact";
  }
  if (auto v = om.Optional("inertia_option")) b.option_b = v->OneOf({"A", "B"}, "(Cardona's options)") == "B";
  if (auto v = om.Optional("modal_damping")) {
    b.modal_damping = v->Number();
    if (b.modal_damping < 0) v->Fail("damping ratio must be >= 0");
  }
  om.CheckNoUnknownKeys();
}

// One item of `bodies`; its nodes join `nodes`.
SceneBodySpec ParseBody(const YamlValue& item, const SceneSpec& scene, NodeNames& nodes) {
  YamlMap m = item.Map();
  SceneBodySpec b;
  b.where = item.Where();
  b.name = m.Required("name").String();
  for (const auto& other : scene.bodies) {
    if (other.name == b.name) item.Fail("body name '" + b.name + "' used twice");
  }
  if (auto t = m.Optional("type")) b.type = t->Kind<BodyType>("body type");
  if (b.type == BodyType::kSuperelement) {
    b.superelement = m.Required("superelement").String();
  } else {
    ParseRigidBody(m, b);
  }
  if (auto p = m.Optional("placement")) {
    YamlMap pm = p->Map();
    if (auto v = pm.Optional("position")) b.position = v->Vector3();
    if (auto v = pm.Optional("rotation")) b.rotation = v->Vector3();
    pm.CheckNoUnknownKeys();
  }
  YamlValue node_map = m.Required("nodes");
  for (const auto& [iname, scene_node] : node_map.Map().Entries()) {
    if (b.type == BodyType::kRigid && iname != "com" && !b.points.count(iname)) {
      scene_node.Fail("rigid body '" + b.name + "' has no point '" + iname +
                      "' (define it under 'points'; 'com' is the centre of mass)");
    }
    b.nodes[iname] = scene_node.String();
    nodes.Add(scene_node.String());
  }
  if (b.type == BodyType::kRigid && !b.nodes.count("com")) {
    b.nodes["com"] = b.name + ".com";
    nodes.Add(b.nodes["com"]);
  }
  if (auto o = m.Optional("options")) ParseBodyOptions(*o, b);
  m.CheckNoUnknownKeys();
  return b;
}

// One item of `joints`.
SceneJointSpec ParseJoint(const YamlValue& item, const SceneSpec& scene, const NodeNames& nodes) {
  YamlMap m = item.Map();
  SceneJointSpec j;
  j.where = item.Where();
  YamlValue type = m.Required("type");
  // `clamp`: a rigid joint to the ground, the one joint word that is not a JointType.
  const bool clamp = type.String() == "clamp";
  if (!clamp) {
    const std::string word = type.String();
    if (!KindOf<JointType>(word))
      type.Fail("unknown joint type '" + word + "' (known: clamp, " + JoinWords(WordsOf<JointType>()) + ")");
    j.type = *KindOf<JointType>(word);
  }
  const bool axial = j.type == JointType::kRevolute || j.type == JointType::kPrismatic ||
                     j.type == JointType::kCylindrical || j.type == JointType::kUniversal;
  j.node = nodes.Check(m.Required("node"));
  if (auto p = m.Optional("parent")) {
    j.parent = nodes.Check(*p);
    if (j.parent == j.node) p->Fail("a node cannot be its own parent");
    if (clamp) type.Fail("a clamp holds a node to the ground; between two nodes use 'rigid'");
  } else if (j.type == JointType::kRigid && !clamp) {
    type.Fail("a rigid joint needs a 'parent' node (to the ground use 'clamp')");
  }
  if (axial) {
    YamlValue axis = m.Required("axis");
    j.axis = axis.Vector3();
    if (j.axis.norm() == 0) axis.Fail("axis must not be zero");
    if (j.type == JointType::kUniversal) {
      YamlValue axis2 = m.Required("axis2");
      j.axis2 = axis2.Vector3();
      if (std::abs(j.axis.normalized().dot(j.axis2.normalized())) > 1e-6) {
        axis2.Fail("the two axes of a universal joint must be perpendicular");
      }
    }
    if (auto v = m.Optional("prescribed")) {
      if (j.type == JointType::kCylindrical || j.type == JointType::kUniversal) {
        v->Fail(std::string("prescribed motion of a ") + Name(j.type) +
                " joint is not supported; use revolute or prismatic");
      }
      j.prescribed = v->String();
      if (!scene.functions.count(j.prescribed))
        v->Fail("time function '" + j.prescribed + "' is not defined under 'functions'");
    }
  }
  if (auto v = m.Optional("cut")) {
    j.cut = v->Bool();
    if (j.cut && !j.prescribed.empty()) {
      v->Fail("a prescribed joint cannot be cut: its coordinate carries the drive (cut another joint of the loop)");
    }
  }
  m.CheckNoUnknownKeys();
  return j;
}

// One item of `loads`.
SceneLoadSpec ParseLoad(const YamlValue& item, const SceneSpec& scene, const NodeNames& nodes) {
  YamlMap m = item.Map();
  SceneLoadSpec l;
  l.where = item.Where();
  l.type = m.Required("type").Kind<LoadType>("load type");
  if (l.type == LoadType::kForce) {
    l.node = nodes.Check(m.Required("node"));
    if (auto v = m.Optional("force")) l.force = v->Vector3();
    if (auto v = m.Optional("moment")) l.moment = v->Vector3();
    if (auto v = m.Optional("follower")) l.follower = v->Bool();
    if (auto v = m.Optional("function")) {
      l.function = v->String();
      if (!scene.functions.count(l.function))
        v->Fail("time function '" + l.function + "' is not defined under 'functions'");
    }
  } else if (l.type == LoadType::kGravity) {
    l.g = m.Required("g").Vector3();
  } else {  // kSpring
    l.node = nodes.Check(m.Required("node"));
    auto node_b = m.Optional("node_b");
    auto point = m.Optional("point");
    if (bool(node_b) == bool(point)) item.Fail("a spring needs exactly one of node_b and point for its other end");
    if (node_b) l.node_b = nodes.Check(*node_b);
    if (point) l.point = point->Vector3();
    YamlValue k = m.Required("stiffness");
    l.stiffness = k.Number();
    if (l.stiffness < 0) k.Fail("stiffness must be >= 0");
    if (auto v = m.Optional("damping")) {
      l.damping = v->Number();
      if (l.damping < 0) v->Fail("damping must be >= 0");
    }
    if (auto v = m.Optional("free_length")) {
      l.free_length = v->Number();
      if (l.free_length < 0) v->Fail("free length must be >= 0");
    }
  }
  m.CheckNoUnknownKeys();
  return l;
}

// `initial_state`: the state of another run to start from.
void ParseInitialState(const YamlValue& initial, SceneSpec& scene) {
  YamlMap m = initial.Map();
  const YamlValue from = m.Required("from");
  scene.initial_state.from = from.String();
  scene.initial_state.where = initial.Where();
  if (auto t = m.Optional("time")) scene.initial_state.time = t->Number();
  m.CheckNoUnknownKeys();
  if (scene.initial_state.from.empty()) from.Fail("initial_state.from: give the folder of a femb-solve run");
}

// `initial_velocity`: per node, linear and angular velocities or joint rates.
void ParseInitialVelocity(const YamlValue& initial, const NodeNames& nodes, SceneSpec& scene) {
  for (const auto& [node, value] : initial.Map().Entries()) {
    YamlMap m = value.Map();
    std::pair<Eigen::Vector3d, Eigen::Vector3d> v{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    if (auto x = m.Optional("linear")) v.first = x->Vector3();
    if (auto x = m.Optional("angular")) v.second = x->Vector3();
    auto joint = m.Optional("joint");
    m.CheckNoUnknownKeys();
    if (!nodes.Has(node)) value.Fail("node '" + node + "' is not a node of any body");
    if (joint) {
      if (m.Optional("linear") || m.Optional("angular"))
        value.Fail("give either joint rates or linear/angular velocities");
      std::vector<double> rates;
      for (const YamlValue& r : joint->List()) rates.push_back(r.Number());
      scene.initial_joint_rates[node] = rates;
    } else {
      scene.initial_velocities[node] = v;
    }
  }
}

// `analysis`.
void ParseAnalysis(const YamlValue& analysis, SceneAnalysisSpec& a) {
  YamlMap m = analysis.Map();
  a.type = m.Required("type").Kind<AnalysisType>("analysis type");
  if (auto v = m.Optional("count")) {
    a.mode_count = int(v->Integer());
    if (a.mode_count < 1) v->Fail("needs at least 1 mode");
  }
  if (auto v = m.Optional("about")) a.modes_about_static = v->OneOf({"initial", "static"}) == "static";
  if (auto v = m.Optional("end_time")) a.end_time = v->PositiveNumber();
  if (auto v = m.Optional("steps")) {
    a.steps = int(v->Integer());
    if (a.steps < 1) v->Fail("needs at least 1 step");
  }
  if (auto v = m.Optional("step")) {
    if (v->IsScalar() && v->String() == "auto") {
      a.adaptive_step = true;
    } else {
      a.step = v->PositiveNumber();
    }
  }
  if (auto v = m.Optional("step_tolerance")) a.step_tolerance = v->PositiveNumber();
  std::optional<YamlValue> min_step = m.Optional("min_step"), max_step = m.Optional("max_step");
  if (min_step) a.min_step = min_step->PositiveNumber();
  if (max_step) a.max_step = max_step->PositiveNumber();
  if (min_step && max_step && a.min_step > a.max_step) {
    min_step->Fail("min_step " + min_step->String() + " is above max_step " + max_step->String());
  }
  if (auto v = m.Optional("output_step")) a.output_step = v->PositiveNumber();
  if (auto v = m.Optional("rho_inf")) {
    a.rho_inf = v->Number();
    if (a.rho_inf < 0 || a.rho_inf > 1) v->Fail("rho_inf must be in [0, 1]");
  }
  if (auto v = m.Optional("integrator")) a.integrator = v->OneOfKinds<Integrator>();
  if (auto v = m.Optional("tolerance")) a.tolerance = v->PositiveNumber();
  if (auto v = m.Optional("max_iterations")) a.max_iterations = int(v->NonNegativeInteger());
  if (auto v = m.Optional("output_every")) a.output_every = std::max(1, int(v->NonNegativeInteger()));
  if (auto v = m.Optional("jacobian_reuse")) a.jacobian_reuse = v->OneOfKinds<JacobianReuse>();
  if (auto v = m.Optional("gyroscopic_tangent")) a.gyroscopic_tangent = v->Bool();
  if (auto v = m.Optional("body_matrices_every")) {
    a.body_matrices_every = int(v->Integer());
    if (a.body_matrices_every < 1) v->Fail("body_matrices_every must be a whole number of steps, at least 1");
  }
  if (auto v = m.Optional("body_matrices_kept")) a.body_matrices_kept = v->OneOfKinds<BodyMatricesKept>();
  m.CheckNoUnknownKeys();
}

// `outputs.stress_exclude`: the region left out of the largest stresses.
void ParseStressExclude(const YamlValue& exclude, SceneSpec& scene) {
  YamlMap em = exclude.Map();
  scene.stress_exclude.where = exclude.Where();
  const YamlValue distance = em.Required("distance");
  scene.stress_exclude.distance = distance.Number();
  if (!(scene.stress_exclude.distance >= 0)) distance.Fail("stress_exclude.distance must be >= 0 (a length)");
  if (auto list = em.Optional("interfaces")) {
    for (const YamlValue& item : list->List()) {
      const std::string entry = item.String();
      if (entry.find('.') == std::string::npos)
        item.Fail("stress_exclude.interfaces: '" + entry + "' is not <body>.<interface>");
      scene.stress_exclude.interfaces.push_back(entry);
    }
  }
  em.CheckNoUnknownKeys();
}

// One item of `outputs.probes`: a node probe or a point probe.
SceneProbeSpec ParseProbe(const YamlValue& item, const NodeNames& nodes, SceneSpec& scene) {
  YamlMap pm = item.Map();
  SceneProbeSpec p;
  p.where = item.Where();
  p.name = pm.Required("name").String();
  const auto body = pm.Optional("body");
  if (body) {
    // A point probe: a body and a point.
    p.body = body->String();
    p.point = pm.Required("point").Vector3();
    if (pm.Optional("node"))
      item.Fail("probe '" + p.name +
                "': give either node (node quantities) or body and point (point quantities), not both");
  } else {
    p.node = nodes.Check(pm.Required("node"));
  }
  YamlValue q = pm.Required("quantities");
  static const ProbeQuantity node_quantities[] = {
      ProbeQuantity::kPosition,        ProbeQuantity::kRotation,     ProbeQuantity::kVelocity,
      ProbeQuantity::kAngularVelocity, ProbeQuantity::kAcceleration, ProbeQuantity::kAngularAcceleration,
      ProbeQuantity::kJoint,           ProbeQuantity::kReaction,     ProbeQuantity::kEffort};
  static const ProbeQuantity point_quantities[] = {ProbeQuantity::kPosition, ProbeQuantity::kVelocity,
                                                   ProbeQuantity::kAcceleration, ProbeQuantity::kDeformation,
                                                   ProbeQuantity::kStress};
  const auto names = [](const auto& list) {
    std::string out;
    for (ProbeQuantity x : list) out += std::string(out.empty() ? "" : ", ") + Name(x);
    return out;
  };
  for (const YamlValue& qi : q.List()) {
    const std::string s = qi.String();
    const auto known = [&](const auto& list) {
      return std::find_if(std::begin(list), std::end(list), [&](ProbeQuantity x) { return s == Name(x); });
    };
    const auto in_node = known(node_quantities);
    const auto in_point = known(point_quantities);
    if (in_node == std::end(node_quantities) && in_point == std::end(point_quantities)) {
      qi.Fail("unknown probe quantity '" + s + "' (node probes: " + names(node_quantities) +
              "; point probes, with body and point: " + names(point_quantities) + ")");
    }
    if (body && in_point == std::end(point_quantities)) {
      qi.Fail("probe quantity '" + s +
              "' is a node quantity: give node, not body and point (point probes: " + names(point_quantities) + ")");
    }
    if (!body && in_node == std::end(node_quantities)) {
      qi.Fail("probe quantity '" + s +
              "' needs body and point (e.g. {name: s, body: rod0, point: [x, y, z], quantities: [" + s + "]})");
    }
    p.quantities.push_back(body ? *in_point : *in_node);
    if (p.quantities.back() == ProbeQuantity::kReaction || p.quantities.back() == ProbeQuantity::kEffort)
      scene.reactions = true;
  }
  pm.CheckNoUnknownKeys();
  return p;
}

// `outputs`.
void ParseOutputs(const YamlValue& outputs, const NodeNames& nodes, SceneSpec& scene) {
  YamlMap m = outputs.Map();
  if (auto v = m.Optional("animation")) scene.animation = v->Bool();
  if (auto v = m.Optional("animation_every")) scene.animation_every = int(v->NonNegativeInteger());
  if (auto v = m.Optional("reactions")) scene.reactions = scene.reactions || v->Bool();
  if (auto v = m.Optional("stresses")) scene.stresses = v->Bool();
  if (auto v = m.Optional("principal_stresses")) {
    scene.principal_stresses = v->Bool();
    if (scene.principal_stresses && !scene.stresses)
      v->Fail("principal_stresses: true needs stresses: true (the principal stresses are stress fields)");
  }
  if (auto v = m.Optional("flush_every")) {
    scene.flush_every = v->Number();
    if (!(scene.flush_every >= 0)) v->Fail("flush_every must be >= 0 (seconds of wall time between writes)");
  }
  if (auto v = m.Optional("flush_every_steps")) scene.flush_every_steps = long(v->NonNegativeInteger());
  if (auto exclude = m.Optional("stress_exclude")) ParseStressExclude(*exclude, scene);
  if (auto probes = m.Optional("probes")) {
    for (const YamlValue& item : probes->List()) scene.probes.push_back(ParseProbe(item, nodes, scene));
  }
  m.CheckNoUnknownKeys();
}

}  // namespace

SceneSpec ParseScene(const std::string& text, const std::string& name, const std::vector<std::string>& overrides) {
  YamlDocument doc = YamlDocument::LoadString(text, name);
  for (const auto& o : overrides) doc.Set(o);
  YamlMap root = doc.Root();
  SceneSpec scene;
  scene.file = name;
  scene.name = root.Required("name").String();
  if (auto u = root.Optional("units")) scene.units = u->String();
  if (auto functions = root.Optional("functions")) {
    for (const auto& [fname, value] : functions->Map().Entries()) scene.functions[fname] = ParseFunction(value);
  }
  NodeNames nodes;
  YamlValue bodies = root.Required("bodies");
  for (const YamlValue& item : bodies.List()) scene.bodies.push_back(ParseBody(item, scene, nodes));
  if (scene.bodies.empty()) bodies.Fail("a scene needs at least one body");
  if (auto joints = root.Optional("joints")) {
    for (const YamlValue& item : joints->List()) scene.joints.push_back(ParseJoint(item, scene, nodes));
  }
  if (auto loads = root.Optional("loads")) {
    for (const YamlValue& item : loads->List()) scene.loads.push_back(ParseLoad(item, scene, nodes));
  }
  if (auto initial = root.Optional("initial_state")) ParseInitialState(*initial, scene);
  if (auto initial = root.Optional("initial_velocity")) ParseInitialVelocity(*initial, nodes, scene);
  ParseAnalysis(root.Required("analysis"), scene.analysis);
  if (auto outputs = root.Optional("outputs")) ParseOutputs(*outputs, nodes, scene);
  root.CheckNoUnknownKeys();
  return scene;
}

SceneSpec ReadSceneFile(const std::string& path, const std::vector<std::string>& overrides) {
  return ParseScene(ReadTextFile(path, "scene file"), path, overrides);
}

}  // namespace femb
