// formats/yaml_reader: typed values with their place in the file, checked keys, and --set
// overrides. Every wrong value is one message that starts with FILE:LINE and the key path (or
// "--set key.path" for an override) and says what was expected and what was found.
#include "formats/yaml_reader.h"

#include <gtest/gtest.h>

#include <string>

#include "formats/input_error.h"
#include "test_util.h"

namespace femb {
namespace {

const char* kText =
    "name: bar\n"                // 1
    "size: 0.25\n"               // 2
    "count: 7\n"                 // 3
    "flag: true\n"               // 4
    "axis: [0, 0.6, 0.8]\n"      // 5
    "shape: circle\n"            // 6
    "nested:\n"                  // 7
    "  depth: -3\n"              // 8
    "  items:\n"                 // 9
    "    - {x: 1}\n"             // 10
    "    - {x: 2, extra: 5}\n";  // 11

TEST(YamlReader, TypedValuesAndTheirPlaces) {
  const YamlDocument doc = YamlDocument::LoadString(kText, "part.yaml");
  const YamlMap root = doc.Root();
  EXPECT_EQ(root.Required("name").String(), "bar");
  EXPECT_EQ(root.Required("size").Number(), 0.25);
  EXPECT_EQ(root.Required("size").PositiveNumber(), 0.25);
  EXPECT_EQ(root.Required("count").Integer(), 7);
  EXPECT_EQ(root.Required("count").NonNegativeInteger(), 7);
  EXPECT_TRUE(root.Required("flag").Bool());
  EXPECT_EQ(root.Required("axis").Vector3(), Eigen::Vector3d(0, 0.6, 0.8));
  EXPECT_EQ(root.Required("shape").OneOf({"circle", "rectangle"}), "circle");
  EXPECT_FALSE(root.Optional("absent"));
  const YamlMap nested = root.Required("nested").Map();
  EXPECT_EQ(nested.Required("depth").Integer(), -3);
  const std::vector<YamlValue> items = nested.Required("items").List();
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[1].Map().Required("x").Number(), 2.0);
  // Places: file, line, and the key path with list indices.
  EXPECT_EQ(nested.Required("depth").Where(), "part.yaml:8: nested.depth");
  EXPECT_EQ(items[1].Map().Required("x").Where(), "part.yaml:11: nested.items[1].x");
}

TEST(YamlReader, EachWrongValueIsOneLineWithItsPlace) {
  const YamlDocument doc = YamlDocument::LoadString(kText, "part.yaml");
  const YamlMap root = doc.Root();
  const auto expect = [](const std::string& message, const std::string& start, const std::string& what) {
    EXPECT_EQ(message.rfind(start, 0), 0u) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  };
  expect(test::ErrorOf([&] { root.Required("name").Number(); }), "part.yaml:1: name", "bar");
  expect(test::ErrorOf([&] { root.Required("nested").Map().Required("depth").NonNegativeInteger(); }),
         "part.yaml:8: nested.depth", "-3");
  expect(test::ErrorOf([&] { root.Required("size").Integer(); }), "part.yaml:2: size", "0.25");
  expect(test::ErrorOf([&] {
           root.Required("shape").OneOf({"box", "tube"});
         }),
         "part.yaml:6: shape", "expected box or tube, got 'circle'");
  expect(test::ErrorOf([&] { root.Required("count").Vector3(); }), "part.yaml:3: count", "");
  expect(test::ErrorOf([&] { root.Required("missing"); }), "part.yaml", "missing");
  // Unknown keys: named with their line once the known ones were asked for.
  const YamlMap item = root.Required("nested").Map().Required("items").List()[1].Map();
  item.Required("x");
  expect(test::ErrorOf([&] { item.CheckNoUnknownKeys(); }), "part.yaml:11", "extra");
  const YamlMap first = root.Required("nested").Map().Required("items").List()[0].Map();
  first.Required("x");
  EXPECT_EQ(test::ErrorOf([&] { first.CheckNoUnknownKeys(); }), "");
  // A syntax error names the file, line and column.
  const std::string syntax = test::ErrorOf([] { YamlDocument::LoadString("a: [1, 2\nb: 3\n", "bad.yaml"); });
  EXPECT_EQ(syntax.rfind("bad.yaml:", 0), 0u) << syntax;
  EXPECT_NE(syntax.find("YAML syntax error"), std::string::npos) << syntax;
  // A file that is not there.
  EXPECT_NE(test::ErrorOf([] { YamlDocument::LoadFile("/nonexistent/part.yaml"); }).find("/nonexistent/part.yaml"),
            std::string::npos);
}

TEST(YamlReader, SetOverridesAndSaysSo) {
  YamlDocument doc = YamlDocument::LoadString(kText, "part.yaml");
  doc.Set("size=0.5");
  doc.Set("nested.items[0].x=9");
  doc.Set("nested.new_key=[1, 2, 3]");
  const YamlMap root = doc.Root();
  EXPECT_EQ(root.Required("size").Number(), 0.5);
  EXPECT_EQ(root.Required("size").Where(), "--set size");
  const YamlMap nested = root.Required("nested").Map();
  EXPECT_EQ(nested.Required("items").List()[0].Map().Required("x").Number(), 9.0);
  EXPECT_EQ(nested.Required("new_key").List().size(), 3u);
  // A wrong value given by --set is named as such.
  doc.Set("count=seven");
  const std::string message = test::ErrorOf([&] { doc.Root().Required("count").Integer(); });
  EXPECT_EQ(message.rfind("--set count", 0), 0u) << message;
  // Malformed assignments.
  EXPECT_NE(test::ErrorOf([&] { doc.Set("size"); }).find("expected key.path=value"), std::string::npos);
  EXPECT_NE(test::ErrorOf([&] { doc.Set("=1"); }).find("expected key.path=value"), std::string::npos);
  EXPECT_NE(test::ErrorOf([&] { doc.Set("nested.items[x].x=1"); }).find("malformed list index"), std::string::npos);
  EXPECT_NE(test::ErrorOf([&] { doc.Set("a..b=1"); }).find("empty key"), std::string::npos);
  EXPECT_NE(test::ErrorOf([&] { doc.Set("nested.items[5].x=1"); }), "");
}

}  // namespace
}  // namespace femb
