// Kinds that the input files name by a word (a part's type, a coupling, an integrator, a joint),
// parsed once into enums: the programs choose on the enum, never on the word. Each enum lists
// its words once, in Words<E>::list (a kind may have several words; the first is its name).
// Name gives a kind's word back (messages, files); KindOf reads one; YamlValue::Kind reads one
// from an input file and names the file, line and known words when it is none of them.
#pragma once

#include <concepts>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace femb {

template <class E>
struct KindWord {
  E kind;
  const char* word;
};

/// Words<E>::list: the words of every kind of E, each kind's name first.
template <class E>
struct Words;

/// An enum whose kinds have words.
template <class E>
concept Worded = std::is_enum_v<E> && requires {
  Words<E>::list;
};

/// The kind's name: its first word in Words<E>::list.
template <Worded E>
const char* Name(E kind) {
  for (const KindWord<E>& w : Words<E>::list) {
    if (w.kind == kind) return w.word;
  }
  return "?";
}

/// The kind a word names, if any.
template <Worded E>
std::optional<E> KindOf(std::string_view word) {
  for (const KindWord<E>& w : Words<E>::list) {
    if (word == w.word) return w.kind;
  }
  return std::nullopt;
}

/// Every word of E, in the order of the list (for "known: ..." in messages).
template <Worded E>
std::vector<std::string> WordsOf() {
  std::vector<std::string> out;
  for (const KindWord<E>& w : Words<E>::list) out.emplace_back(w.word);
  return out;
}

/// The words joined as a message lists them: "a, b, c".
std::string JoinWords(const std::vector<std::string>& words);

// ---- parts (formats/PART_FORMAT.md) ----

/// `type` of a part.
enum class PartType { kBeam, kSolid, kImported };
template <>
struct Words<PartType> {
  static constexpr KindWord<PartType> list[] = {
      {PartType::kBeam, "beam"}, {PartType::kSolid, "solid"}, {PartType::kImported, "imported"}};
};

/// `reduction.method`.
enum class ReductionMethod { kCraigBampton, kFreeInterface, kGeneral };
template <>
struct Words<ReductionMethod> {
  static constexpr KindWord<ReductionMethod> list[] = {{ReductionMethod::kCraigBampton, "craig_bampton"},
                                                       {ReductionMethod::kFreeInterface, "free_interface"},
                                                       {ReductionMethod::kGeneral, "general"}};
};

/// `reduction.solver`: the linear algebra of the reduction's interior (its one factor and the
/// eigen solve). kCholmod: CHOLMOD's supernodal Cholesky and femb's block shift-invert Lanczos on
/// one process; kPetsc: MUMPS' distributed Cholesky and SLEPc's Krylov-Schur over the MPI ranks
/// femb-reduce runs on (mpirun).
enum class ReductionSolver { kCholmod, kPetsc };
template <>
struct Words<ReductionSolver> {
  static constexpr KindWord<ReductionSolver> list[] = {{ReductionSolver::kCholmod, "cholmod"},
                                                       {ReductionSolver::kPetsc, "petsc"}};
};

/// `reduction.floating_frame`; kInterface is written `interface:<name>`.
enum class FloatingFrameType { kCenterOfMass, kMeanAxes, kCardona, kInterface };
template <>
struct Words<FloatingFrameType> {
  static constexpr KindWord<FloatingFrameType> list[] = {{FloatingFrameType::kCenterOfMass, "center_of_mass"},
                                                         {FloatingFrameType::kMeanAxes, "mean_axes"},
                                                         {FloatingFrameType::kCardona, "cardona"},
                                                         {FloatingFrameType::kInterface, "interface"}};
};

/// `reduction.modal_derivatives.of`: which reduced coordinates are paired.
enum class DerivativePairs { kAll, kStatic, kInternal };
template <>
struct Words<DerivativePairs> {
  static constexpr KindWord<DerivativePairs> list[] = {
      {DerivativePairs::kAll, "all"}, {DerivativePairs::kStatic, "static"}, {DerivativePairs::kInternal, "internal"}};
};

/// `interfaces[].coupling`: how an interface node holds its surface's nodes.
enum class Coupling {
  kRbe2,  ///< rigidly
  kRbe3,  ///< by a weighted average (the surface keeps its own deformation)
};
template <>
struct Words<Coupling> {
  static constexpr KindWord<Coupling> list[] = {{Coupling::kRbe2, "rbe2"}, {Coupling::kRbe3, "rbe3"}};
};

/// `beam.section.shape`.
enum class SectionShape { kCircle, kTube, kRectangle, kGeneral };
template <>
struct Words<SectionShape> {
  static constexpr KindWord<SectionShape> list[] = {{SectionShape::kCircle, "circle"},
                                                    {SectionShape::kTube, "tube"},
                                                    {SectionShape::kRectangle, "rectangle"},
                                                    {SectionShape::kGeneral, "general"}};
};

/// `solid.shape`, or kFile for a geometry or mesh file.
enum class SolidShape { kFile, kBox, kPlate, kCylinder, kTube };
template <>
struct Words<SolidShape> {
  static constexpr KindWord<SolidShape> list[] = {{SolidShape::kBox, "box"},
                                                  {SolidShape::kPlate, "plate"},
                                                  {SolidShape::kCylinder, "cylinder"},
                                                  {SolidShape::kTube, "tube"}};
};

/// `interfaces[].select.shape`: the surface (or box) that picks mesh nodes.
enum class SelectionShape { kCylinder, kSphere, kBox, kPlane };
template <>
struct Words<SelectionShape> {
  static constexpr KindWord<SelectionShape> list[] = {{SelectionShape::kCylinder, "cylinder"},
                                                      {SelectionShape::kSphere, "sphere"},
                                                      {SelectionShape::kBox, "box"},
                                                      {SelectionShape::kPlane, "plane"}};
};

/// Matrix files of other FE codes (`imported.format`, femb-reduce --matrix-format).
enum class MatrixFormat { kCalculix, kAbaqus, kAbaqusCoordinate, kMatrixMarket, kNastran, kAnsys };
template <>
struct Words<MatrixFormat> {
  static constexpr KindWord<MatrixFormat> list[] = {{MatrixFormat::kCalculix, "calculix"},
                                                    {MatrixFormat::kAbaqus, "abaqus"},
                                                    {MatrixFormat::kAbaqusCoordinate, "abaqus_coordinate"},
                                                    {MatrixFormat::kMatrixMarket, "matrix_market"},
                                                    {MatrixFormat::kNastran, "nastran"},
                                                    {MatrixFormat::kAnsys, "ansys"}};
};

// ---- scenes (formats/SCENE_FORMAT.md) and the solver ----

/// `analysis.type`.
enum class AnalysisType { kStatic, kDynamic, kModes };
template <>
struct Words<AnalysisType> {
  static constexpr KindWord<AnalysisType> list[] = {
      {AnalysisType::kStatic, "static"}, {AnalysisType::kDynamic, "dynamic"}, {AnalysisType::kModes, "modes"}};
};

/// `analysis.integrator`: the dynamic analysis' time integrator.
enum class Integrator {
  kGeneralizedAlpha,  ///< Lie-group generalized-alpha, numerical damping set by rho_inf
  kMidpoint,          ///< momentum-conserving midpoint (Simo-Wong for rigid bodies), no damping
  kRadau,             ///< three-stage Radau IIA, order 5, L-stable
};
template <>
struct Words<Integrator> {
  static constexpr KindWord<Integrator> list[] = {{Integrator::kGeneralizedAlpha, "generalized_alpha"},
                                                  {Integrator::kMidpoint, "midpoint"},
                                                  {Integrator::kRadau, "radau"}};
};

/// `analysis.jacobian_reuse`: when Newton factors its iteration matrix anew (IterationMatrix,
/// solver/analysis/dynamic_step.h). true and false are the words from before `step` existed.
enum class JacobianReuse {
  kNone,   ///< every iteration: full Newton
  kStep,   ///< the first iteration of every step; its later iterations keep that factor while
           ///< each of them contracts the residual at least tenfold (modified Newton within the step)
  kSteps,  ///< kept across steps of the same size; anew after reuse_max_iterations iterations with it
};
template <>
struct Words<JacobianReuse> {
  static constexpr KindWord<JacobianReuse> list[] = {{JacobianReuse::kStep, "step"},
                                                     {JacobianReuse::kSteps, "steps"},
                                                     {JacobianReuse::kNone, "none"},
                                                     {JacobianReuse::kSteps, "true"},
                                                     {JacobianReuse::kNone, "false"}};
};

/// `analysis.body_matrices_kept`: which of a body's matrices body_matrices_every keeps between
/// computations.
enum class BodyMatricesKept {
  kInertia,  ///< mass and gyroscopic (the inertia force's); the tangents computed every time
  kAll,      ///< all: also the elastic tangent and the inertia's configuration tangent
};
template <>
struct Words<BodyMatricesKept> {
  static constexpr KindWord<BodyMatricesKept> list[] = {{BodyMatricesKept::kInertia, "inertia"},
                                                        {BodyMatricesKept::kAll, "all"}};
};

/// `bodies[].type`.
enum class BodyType { kSuperelement, kRigid };
template <>
struct Words<BodyType> {
  static constexpr KindWord<BodyType> list[] = {{BodyType::kSuperelement, "superelement"}, {BodyType::kRigid, "rigid"}};
};

/// `joints[].type` (solver/joints/node_joint.h). The scene's `clamp` is a rigid joint to the
/// ground (SceneJointSpec, no parent).
enum class JointType { kRigid, kRevolute, kPrismatic, kCylindrical, kSpherical, kUniversal };
template <>
struct Words<JointType> {
  static constexpr KindWord<JointType> list[] = {
      {JointType::kRigid, "rigid"},         {JointType::kRevolute, "revolute"},
      {JointType::kPrismatic, "prismatic"}, {JointType::kCylindrical, "cylindrical"},
      {JointType::kSpherical, "spherical"}, {JointType::kUniversal, "universal"}};
};

/// `loads[].type`.
enum class LoadType { kForce, kGravity, kSpring };
template <>
struct Words<LoadType> {
  static constexpr KindWord<LoadType> list[] = {
      {LoadType::kForce, "force"}, {LoadType::kGravity, "gravity"}, {LoadType::kSpring, "spring"}};
};

}  // namespace femb
