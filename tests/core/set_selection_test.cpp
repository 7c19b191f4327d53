// The one set-selection syntax of every command (N, A:B, 0,2,5-7).
#include "tomorig/core/set_selection.h"

#include <gtest/gtest.h>

#include "tomorig/core/error.h"

namespace tomorig {
namespace {

using Sets = std::vector<std::uint64_t>;

std::string bad_input_message(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    return e.what();
  }
  ADD_FAILURE() << "no bad_input thrown";
  return {};
}

TEST(SetSelection, NoneGivenChoosesEverySet) {
  const SetSelection s;
  EXPECT_TRUE(s.all());
  EXPECT_EQ(s.indices(3), (Sets{0, 1, 2}));
  EXPECT_EQ(s.leading_count("x"), 0u);
}

TEST(SetSelection, BareNumberIsACountOfLeadingSets) {
  const SetSelection s = SetSelection::parse("3");
  EXPECT_EQ(s.indices(10), (Sets{0, 1, 2}));
  EXPECT_EQ(s.range(10), (std::pair<std::uint64_t, std::uint64_t>{0, 3}));
  EXPECT_EQ(s.leading_count("x"), 3u);
  EXPECT_NE(bad_input_message([&] { s.indices(2); }).find("holds 2 sets"), std::string::npos);
}

TEST(SetSelection, RangesAreHalfOpenWithOptionalEnds) {
  EXPECT_EQ(SetSelection::parse("2:5").indices(10), (Sets{2, 3, 4}));
  EXPECT_EQ(SetSelection::parse("7:").indices(10), (Sets{7, 8, 9}));
  EXPECT_EQ(SetSelection::parse(":2").indices(10), (Sets{0, 1}));
  EXPECT_EQ(SetSelection::parse(":4").leading_count("x"), 4u);
  EXPECT_EQ(SetSelection::parse("0:").leading_count("x"), 0u);
  EXPECT_NE(bad_input_message([] { SetSelection::parse("1:9").range(5); }).find("--sets '1:9'"), std::string::npos);
  EXPECT_NE(bad_input_message([] { SetSelection::parse("5:5"); }).find("empty"), std::string::npos);
  EXPECT_NE(bad_input_message([] { SetSelection::parse("7:").range(5); }).find("holds 5 sets"), std::string::npos);
}

TEST(SetSelection, ListsTakeSingleSetsAndInclusiveRanges) {
  const SetSelection s = SetSelection::parse("5-7, 0,2,2");
  EXPECT_EQ(s.indices(10), (Sets{0, 2, 5, 6, 7}));
  EXPECT_EQ(SetSelection::parse("4-4").indices(10), (Sets{4}));
  EXPECT_EQ(SetSelection::parse("3-5").range(10), (std::pair<std::uint64_t, std::uint64_t>{3, 6}));
  EXPECT_EQ(SetSelection::parse("0-2").leading_count("x"), 3u);
  EXPECT_NE(bad_input_message([&] { s.range(10); }).find("consecutive"), std::string::npos);
  EXPECT_NE(bad_input_message([&] { s.indices(6); }).find("set 7 is past the end"), std::string::npos);
  EXPECT_NE(bad_input_message([&] { s.leading_count("the results file holds sets from 0"); }).find("from 0"),
            std::string::npos);
}

TEST(SetSelection, MalformedTextNamesTheOptionAndTheSyntax) {
  for (const char* text : {"", "x", "1:x", "3-1", "1,,2", "-2", "0"}) {
    const std::string m = bad_input_message([&] { SetSelection::parse(text, "--max-sets"); });
    EXPECT_NE(m.find("--max-sets"), std::string::npos) << text << ": " << m;
    EXPECT_NE(m.find("0,2,5-7"), std::string::npos) << text << ": " << m;
  }
}

}  // namespace
}  // namespace tomorig
