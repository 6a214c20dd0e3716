// The kinds of formats/kinds.h and their reading from YAML (formats/yaml_reader.h): every word
// reads back as its kind, every kind's name reads back as itself, words are unique within an
// enum, and a word that names no kind stops with one line naming the file, line, key and the
// known words.
#include "formats/kinds.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "formats/scene_file.h"
#include "formats/vtk_cells.h"
#include "formats/yaml_reader.h"
#include "test_util.h"

namespace femb {
namespace {

// Every word reads back as its own kind, every kind has a name that reads back, no word twice.
template <Worded E>
void ExpectWordsReadBack(const char* what) {
  std::set<std::string> seen;
  for (const KindWord<E>& w : Words<E>::list) {
    EXPECT_TRUE(seen.insert(w.word).second) << what << ": word '" << w.word << "' twice";
    ASSERT_TRUE(KindOf<E>(w.word).has_value()) << what << ": " << w.word;
    EXPECT_EQ(*KindOf<E>(w.word), w.kind) << what << ": " << w.word;
    EXPECT_EQ(KindOf<E>(Name(w.kind)), w.kind) << what << ": the name of '" << w.word << "'";
  }
  EXPECT_FALSE(KindOf<E>("").has_value()) << what;
  EXPECT_FALSE(KindOf<E>("no such word").has_value()) << what;
}

TEST(Kinds, EveryWordReadsBackAsItsKind) {
  ExpectWordsReadBack<PartType>("PartType");
  ExpectWordsReadBack<ReductionMethod>("ReductionMethod");
  ExpectWordsReadBack<ReductionSolver>("ReductionSolver");
  ExpectWordsReadBack<FloatingFrameType>("FloatingFrameType");
  ExpectWordsReadBack<DerivativePairs>("DerivativePairs");
  ExpectWordsReadBack<Coupling>("Coupling");
  ExpectWordsReadBack<SectionShape>("SectionShape");
  ExpectWordsReadBack<SolidShape>("SolidShape");
  ExpectWordsReadBack<SelectionShape>("SelectionShape");
  ExpectWordsReadBack<MatrixFormat>("MatrixFormat");
  ExpectWordsReadBack<AnalysisType>("AnalysisType");
  ExpectWordsReadBack<Integrator>("Integrator");
  ExpectWordsReadBack<JacobianReuse>("JacobianReuse");
  ExpectWordsReadBack<BodyMatricesKept>("BodyMatricesKept");
  ExpectWordsReadBack<BodyType>("BodyType");
  ExpectWordsReadBack<JointType>("JointType");
  ExpectWordsReadBack<LoadType>("LoadType");
  ExpectWordsReadBack<TimeFunctionType>("TimeFunctionType");
  ExpectWordsReadBack<ProbeQuantity>("ProbeQuantity");
  ExpectWordsReadBack<CellType>("CellType");
}

TEST(Kinds, AnAliasReadsAsItsKindAndTheNameIsTheFirstWord) {
  // jacobian_reuse's true and false are the words from before `step` existed.
  EXPECT_EQ(KindOf<JacobianReuse>("true"), JacobianReuse::kSteps);
  EXPECT_EQ(KindOf<JacobianReuse>("false"), JacobianReuse::kNone);
  EXPECT_STREQ(Name(JacobianReuse::kSteps), "steps");
  EXPECT_STREQ(Name(JacobianReuse::kNone), "none");
  EXPECT_EQ(JoinWords(WordsOf<Coupling>()), "rbe2, rbe3");
}

TEST(Kinds, YamlReadsAKindOrNamesTheLineAndTheKnownWords) {
  const YamlDocument doc = YamlDocument::LoadString("a: rbe3\nb: rbe4\nc: craig_bampton\nd: modal\n", "part.yaml");
  const YamlMap root = doc.Root();
  EXPECT_EQ(root.Required("a").Kind<Coupling>("coupling"), Coupling::kRbe3);
  EXPECT_EQ(test::ThrownMessage([&] { root.Required("b").Kind<Coupling>("coupling"); }),
            "part.yaml:2: b: unknown coupling 'rbe4' (known: rbe2, rbe3)");
  EXPECT_EQ(root.Required("c").OneOfKinds<ReductionMethod>(), ReductionMethod::kCraigBampton);
  EXPECT_EQ(test::ThrownMessage([&] { root.Required("d").OneOfKinds<ReductionMethod>(); }),
            "part.yaml:4: d: expected craig_bampton, free_interface or general, got 'modal'");
}

TEST(Kinds, ACommandLineOverrideIsNamedAsSuch) {
  YamlDocument doc = YamlDocument::LoadString("coupling: rbe2\n", "part.yaml");
  doc.Set("coupling=rbe5");
  const YamlMap root = doc.Root();
  const std::string message = test::ThrownMessage([&] { root.Required("coupling").Kind<Coupling>("coupling"); });
  EXPECT_NE(message.find("--set coupling"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown coupling 'rbe5'"), std::string::npos) << message;
}

}  // namespace
}  // namespace femb
