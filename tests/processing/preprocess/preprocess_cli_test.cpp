// `tomorig preprocess` end to end on a small simulated session.
#include <fstream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "cli_runner.h"

namespace tomorig::testing {
namespace {

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

// One simulated session shared by the suite: simulating is the slow part.
class PreprocessCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!tomorig_built()) return;
    suite_dir_ = std::make_unique<TempDir>();
    const CliResult sim = run_tomorig("simulate --sets 2 --ppp 0.01 -o " + shell_quoted((*suite_dir_ / "s.h5").string()));
    simulated_ = sim.exit_code == 0;
    simulate_error_ = sim.err;
  }
  static void TearDownTestSuite() {
    suite_dir_.reset();
  }
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "the tomorig binary is not built";
    ASSERT_TRUE(simulated_) << simulate_error_;
    session_ = *suite_dir_ / "s.h5";
  }
  static inline std::unique_ptr<TempDir> suite_dir_;
  static inline bool simulated_ = false;
  static inline std::string simulate_error_;
  TempDir dir_;
  std::filesystem::path session_;
};

TEST_F(PreprocessCli, WritesAReadableSessionWithTheSameSets) {
  const auto chain = dir_ / "chain.toml";
  write_text(chain,
             "[[preprocess.steps]]\nkind = \"subtract_minimum\"\n"
             "[[preprocess.steps]]\nkind = \"subtract_local_minimum\"\nsize = 5\n"
             "[[preprocess.steps]]\nkind = \"median\"\n");
  const auto out = dir_ / "p.h5";
  const CliResult r = run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                                  shell_quoted(chain.string()) + " -o " + shell_quoted(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Two passes (the minimum, then the output), each reported on stderr.
  EXPECT_NE(r.err.find("pass 1/2, set 2/2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pass 2/2, set 2/2"), std::string::npos) << r.err;

  // The output opens as a session (inspect reads it with SessionReader) with the same sets.
  const CliResult inspect = run_tomorig("inspect --json " + shell_quoted(out.string()));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  EXPECT_NE(inspect.out.find("\"sets\": 2"), std::string::npos) << inspect.out;
  EXPECT_NE(inspect.out.find("\"Mono16\""), std::string::npos) << inspect.out;
  EXPECT_EQ(inspect.out.find("\"Mono12\""), std::string::npos) << inspect.out;

  // A sub-range of sets.
  const auto one = dir_ / "one.h5";
  const CliResult sub = run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                                    shell_quoted(chain.string()) + " --sets 1:2 -o " + shell_quoted(one.string()));
  ASSERT_EQ(sub.exit_code, 0) << sub.err;
  const CliResult inspect_one = run_tomorig("inspect --json " + shell_quoted(one.string()));
  EXPECT_NE(inspect_one.out.find("\"sets\": 1"), std::string::npos) << inspect_one.out;
}

// The pixels themselves, seen through the CLI only (this suite does not link storage): a
// clip above every value must leave all-zero frames, which a flat-field step then refuses as
// a dark bright field, while the unprocessed session is accepted as one.
// Issue 23: an existing output was found only after the sequence passes (minutes on a long
// session). Now it is refused before the first pass, and kept.
TEST_F(PreprocessCli, AnExistingOutputIsRefusedBeforeAnyPass) {
  const auto chain = dir_ / "chain.toml";
  write_text(chain, "[[preprocess.steps]]\nkind = \"subtract_minimum\"\n");
  const auto out = dir_ / "p.h5";
  write_text(out, "an earlier output");
  const CliResult r = run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                                  shell_quoted(chain.string()) + " -o " + shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("already exists"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("pass 1/"), std::string::npos) << r.err;
  EXPECT_EQ(read_text_file(out), "an earlier output");
}

TEST_F(PreprocessCli, ClipAboveEveryValueLeavesZeroFrames) {
  const auto clip = dir_ / "clip.toml";
  write_text(clip, "[[preprocess.steps]]\nkind = \"clip\"\nlevel = 100000\n");
  const auto zero = dir_ / "zero.h5";
  ASSERT_EQ(run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                        shell_quoted(clip.string()) + " -o " + shell_quoted(zero.string()))
                .exit_code,
            0);
  const auto flat_zero = dir_ / "flat_zero.toml";
  write_text(flat_zero, "[[preprocess.steps]]\nkind = \"flat_field\"\nfile = \"" + zero.string() + "\"\n");
  const CliResult refused = run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                                        shell_quoted(flat_zero.string()) + " -o " +
                                        shell_quoted((dir_ / "f1.h5").string()));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("is dark (mean 0)"), std::string::npos) << refused.err;

  const auto flat_raw = dir_ / "flat_raw.toml";
  write_text(flat_raw, "[[preprocess.steps]]\nkind = \"flat_field\"\nfile = \"" + session_.string() + "\"\n");
  const CliResult accepted = run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                                         shell_quoted(flat_raw.string()) + " -o " +
                                         shell_quoted((dir_ / "f2.h5").string()));
  EXPECT_EQ(accepted.exit_code, 0) << accepted.err;
}

// The sequence statistics come from the selected sets only: the minimum over one set is that
// set's own frame, so subtracting it leaves zero frames (a flat field then refuses them as
// dark); over both sets of the session it would not (particles move between sets).
TEST_F(PreprocessCli, SequenceStatisticsComeFromTheSelectedSetsOnly) {
  const auto minimum = dir_ / "minimum.toml";
  write_text(minimum, "[[preprocess.steps]]\nkind = \"subtract_minimum\"\n");
  // This suite's session through `chain` (with `extra` options) into `out`.
  auto preprocess = [&](const std::filesystem::path& chain, const std::string& extra, const std::filesystem::path& out) {
    return run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                       shell_quoted(chain.string()) + extra + " -o " + shell_quoted(out.string()));
  };
  // A flat-field step whose bright field is `session`.
  auto flat_of = [&](const std::filesystem::path& session, const std::string& name) {
    const auto chain = dir_ / (name + ".toml");
    write_text(chain, "[[preprocess.steps]]\nkind = \"flat_field\"\nfile = \"" + session.string() + "\"\n");
    return preprocess(chain, "", dir_ / (name + ".h5"));
  };
  const auto one = dir_ / "min_one.h5";
  ASSERT_EQ(preprocess(minimum, " --sets 1:2", one).exit_code, 0);
  const CliResult dark = flat_of(one, "flat_one");
  EXPECT_EQ(dark.exit_code, 2);
  EXPECT_NE(dark.err.find("is dark (mean 0)"), std::string::npos) << dark.err;

  const auto both = dir_ / "min_both.h5";
  ASSERT_EQ(preprocess(minimum, "", both).exit_code, 0);
  const CliResult lit = flat_of(both, "flat_both");
  EXPECT_EQ(lit.exit_code, 0) << lit.err;
}

TEST_F(PreprocessCli, BadChainFileIsExitTwoNamingTheKey) {
  const auto chain = dir_ / "bad.toml";
  write_text(chain, "[[preprocess.steps]]\nkind = \"median\"\nsize = 4\n");
  const CliResult r = run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                                  shell_quoted(chain.string()) + " -o " + shell_quoted((dir_ / "p.h5").string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("preprocess.steps[0]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("size must be 3 or 5"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "p.h5"));
}

TEST_F(PreprocessCli, BadSetRangeIsExitTwo) {
  const auto chain = dir_ / "chain.toml";
  write_text(chain, "[[preprocess.steps]]\nkind = \"median\"\n");
  const CliResult r = run_tomorig("preprocess --session " + shell_quoted(session_.string()) + " --chain " +
                                  shell_quoted(chain.string()) + " --sets 1:9 -o " +
                                  shell_quoted((dir_ / "p.h5").string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--sets '1:9'"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace tomorig::testing
