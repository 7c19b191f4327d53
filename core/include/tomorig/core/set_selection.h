#pragma once
// The one syntax every command uses to choose sets of a session (docs/cli.md, "Option
// vocabulary"):
//   N         the first N sets                      --sets 10
//   A:B       sets A to B-1 (A: to the end, :B = B)  --sets 5:10
//   list      single sets and inclusive ranges       --sets 0,2,5-7
// A bare number is always a count; one single set k is written k-k (or k:k+1).
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tomorig {

class SetSelection {
 public:
  // Every set (no --sets given).
  SetSelection() = default;
  // Throws tomorig::Error (bad_input) naming `option` and the syntax.
  static SetSelection parse(std::string_view text, std::string_view option = "--sets");

  bool all() const { return kind_ == Kind::all; }
  const std::string& text() const { return text_; }

  // The chosen set indices of a session of `set_count` sets, ascending, without duplicates.
  // Throws bad_input when a set is past the end or nothing is chosen.
  std::vector<std::uint64_t> indices(std::uint64_t set_count) const;
  // [first, end) for commands that work on a contiguous run of sets; a list must be contiguous.
  std::pair<std::uint64_t, std::uint64_t> range(std::uint64_t set_count) const;
  // The N of "N", "0:N" or ":N" (commands that handle only the first N sets); 0 = all sets.
  // Throws bad_input for other selections.
  std::uint64_t leading_count(std::string_view why) const;

 private:
  enum class Kind { all, count, range, list };
  Kind kind_ = Kind::all;
  std::string text_;
  std::string option_ = "--sets";
  std::uint64_t first_ = 0;  // count: N; range: A
  std::uint64_t end_ = 0;    // range: B
  bool open_end_ = false;    // range "A:"
  std::vector<std::uint64_t> list_;
};

}  // namespace tomorig
