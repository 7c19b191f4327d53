// config::TomlDocument: the TOML tree other modules' file readers use instead of toml++.
#include <gtest/gtest.h>

#include <string>

#include "tomorig/config/toml_document.h"

namespace tomorig::testing {
namespace {

using config::TomlDocument;
using config::TomlNode;
using config::TomlSyntaxError;

TEST(TomlDocument, GivesTablesArraysValuesAndTheirLines) {
  const TomlDocument doc = TomlDocument::parse(
      "format = \"x\"\nversion = 1\n\n[led]\npeak_nm = 630.5\non = true\n\n[[cameras]]\nz = [1, 2.5]\n[[cameras]]\nz = []\n",
      "a.toml");
  const TomlNode root = doc.root();
  EXPECT_TRUE(root.is_table());
  EXPECT_EQ(root["format"].as_string(), "x");
  EXPECT_EQ(root["version"].as_integer(), 1);
  EXPECT_TRUE(root["version"].is_integer());
  EXPECT_TRUE(root["version"].is_number());
  EXPECT_EQ(root["version"].line(), 2);
  EXPECT_FALSE(root["format"].as_integer().has_value()) << "a string is not a number";

  const TomlNode led = root["led"];
  EXPECT_TRUE(led.is_table());
  EXPECT_EQ(led.line(), 4);
  EXPECT_DOUBLE_EQ(*led["peak_nm"].as_double(), 630.5);
  EXPECT_FALSE(led["peak_nm"].is_integer());
  EXPECT_EQ(led["on"].as_bool(), true);
  EXPECT_TRUE(led["on"].is_boolean());
  EXPECT_TRUE(led.contains("on"));
  EXPECT_FALSE(led.contains("off"));

  const auto entries = led.entries();
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].first, "on");  // in key order
  EXPECT_EQ(entries[1].first, "peak_nm");

  const TomlNode cameras = root["cameras"];
  EXPECT_TRUE(cameras.is_array_of_tables());
  ASSERT_EQ(cameras.size(), 2u);
  const TomlNode z = cameras[0]["z"];
  ASSERT_EQ(z.size(), 2u);
  EXPECT_EQ(z[0].as_double(), 1.0) << "an integer reads as a float";
  EXPECT_EQ(z[1].as_double(), 2.5);
  EXPECT_EQ(cameras[1]["z"].size(), 0u);
}

TEST(TomlDocument, AbsentNodesAreEmptyNotErrors) {
  const TomlDocument doc = TomlDocument::parse("a = 1\n", "a.toml");
  const TomlNode missing = doc.root()["b"]["c"][3];
  EXPECT_FALSE(missing);
  EXPECT_FALSE(missing.is_table());
  EXPECT_EQ(missing.size(), 0u);
  EXPECT_EQ(missing.line(), 0);
  EXPECT_FALSE(missing.as_double().has_value());
  EXPECT_TRUE(missing.entries().empty());
  EXPECT_FALSE(doc.root()["a"][0]) << "indexing a value is absent";
}

TEST(TomlDocument, ASyntaxErrorNamesItsLine) {
  try {
    TomlDocument::parse("a = 1\nb = = 2\n", "bad.toml");
    FAIL() << "no TomlSyntaxError";
  } catch (const TomlSyntaxError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_FALSE(e.description().empty());
  }
  EXPECT_THROW(TomlDocument::parse_file("/nonexistent/dir/file.toml"), TomlSyntaxError);
}

}  // namespace
}  // namespace tomorig::testing
