// The shared option vocabulary: Δt with units, the positional session, deprecated aliases.
#include "tomorig/core/cli_vocabulary.h"

#include <gtest/gtest.h>

#include "tomorig/core/error.h"

namespace tomorig::cli {
namespace {

void parse(CLI::App& app, std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());  // CLI11 takes them last-first
  app.parse(args);
}

TEST(CliVocabulary, DurationsCarryTheirUnit) {
  EXPECT_DOUBLE_EQ(parse_duration_ns("80us"), 80e3);
  EXPECT_DOUBLE_EQ(parse_duration_ns("1.5ms"), 1.5e6);
  EXPECT_DOUBLE_EQ(parse_duration_ns("200ns"), 200.0);
  EXPECT_DOUBLE_EQ(parse_duration_ns("80 \xC2\xB5s"), 80e3);
  EXPECT_DOUBLE_EQ(parse_duration_ns("0.001s"), 1e6);
  EXPECT_DOUBLE_EQ(parse_duration_ns("0us"), 0.0);
  for (const char* bad : {"80", "us", "80 parsecs", "-3us", ""}) {
    try {
      parse_duration_ns(bad, "--dt");
      ADD_FAILURE() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      EXPECT_NE(std::string(e.what()).find("--dt"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("80us"), std::string::npos) << e.what();
    }
  }
}

TEST(CliVocabulary, DtAndItsOldSpellingsGiveNanoseconds) {
  for (const auto& [args, ns] : {std::pair{std::vector<std::string>{"--dt", "80us"}, 80e3},
                                 std::pair{std::vector<std::string>{"--dt-us", "12.5"}, 12.5e3},
                                 std::pair{std::vector<std::string>{"--dt-ns", "900"}, 900.0}}) {
    CLI::App app;
    std::optional<double> dt;
    add_dt_option(app, dt, "Pulse separation");
    parse(app, args);
    ASSERT_TRUE(dt.has_value()) << args[0];
    EXPECT_DOUBLE_EQ(*dt, ns) << args[0];
  }
  CLI::App app;
  std::optional<double> dt;
  add_dt_option(app, dt, "Pulse separation");
  parse(app, {});
  EXPECT_FALSE(dt.has_value());
  parse(app, {"--dt-ns", "-3"});  // the old spelling's value is checked by the command, as before
  EXPECT_DOUBLE_EQ(dt.value_or(0), -3.0);
}

TEST(CliVocabulary, SessionIsPositionalWithTheOldOptionKept) {
  for (const auto& args : {std::vector<std::string>{"s.h5"}, std::vector<std::string>{"--session", "s.h5"}}) {
    CLI::App app("t", "process");
    std::string session;
    add_session_argument(app, session, "Session file");
    parse(app, args);
    EXPECT_EQ(session, "s.h5");
    EXPECT_NO_THROW(require_session(session, "process"));
  }
  try {
    require_session("", "process");
    ADD_FAILURE() << "an empty session accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("tomorig process SESSION.h5"), std::string::npos) << e.what();
  }
  CLI::App app("t", "inspect");
  std::string session;
  add_session_argument(app, session, "Session file", /*had_option=*/false);
  EXPECT_THROW(parse(app, {"--session", "s.h5"}), CLI::ParseError);
}

TEST(CliVocabulary, DeprecatedSpellingsStoreTheSameValueAndWarnOnce) {
  CLI::App app;
  std::string chain;
  app.add_option("--chain", chain);
  add_deprecated_option(app, "--config", chain, "--chain");
  parse(app, {"--config", "c.toml"});
  EXPECT_EQ(chain, "c.toml");
  EXPECT_FALSE(warn_deprecated("--config", "--chain"));  // already warned by the parse above
  EXPECT_TRUE(warn_deprecated("--never-used-before", "--x"));
}

TEST(CliVocabulary, JsonTakesOnlyAJsonFileAsItsValue) {
  using Args = std::vector<std::string>;
  EXPECT_EQ(apply_json_value_rule({"inspect", "--json", "s.h5"}), (Args{"inspect", "s.h5", "--json"}));
  EXPECT_EQ(apply_json_value_rule({"run", "--json", "out.JSON", "-o", "s.h5"}),
            (Args{"run", "--json", "out.JSON", "-o", "s.h5"}));
  EXPECT_EQ(apply_json_value_rule({"run", "--json", "-o", "s.h5"}), (Args{"run", "--json", "-o", "s.h5"}));
  EXPECT_EQ(apply_json_value_rule({"bench", "record", "--json", "-"}), (Args{"bench", "record", "--json", "-"}));
  EXPECT_EQ(apply_json_value_rule({"inspect", "--json=x.txt", "s.h5"}), (Args{"inspect", "--json=x.txt", "s.h5"}));
  EXPECT_EQ(apply_json_value_rule({"x", "--json", "s.h5", "--", "a"}), (Args{"x", "s.h5", "--json", "--", "a"}));
  // And CLI11 then reads it as the command means it.
  CLI::App app;
  std::string session, file;
  app.add_option("session", session);
  CLI::Option* json = app.add_option("--json", file)->expected(0, 1);
  Args args = apply_json_value_rule({"--json", "s.h5"});
  std::reverse(args.begin(), args.end());
  app.parse(args);
  EXPECT_EQ(session, "s.h5");
  EXPECT_EQ(json->count(), 1u);
  EXPECT_EQ(file, "");
}

}  // namespace
}  // namespace tomorig::cli
