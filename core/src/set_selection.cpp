#include "tomorig/core/set_selection.h"

#include <algorithm>
#include <charconv>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig {
namespace {

constexpr const char* kSyntax = "write N (the first N sets), A:B (sets A to B-1; A: to the end) or a list such as "
                                "0,2,5-7 (a single set k: k-k), set numbers from 0";

std::string trimmed(std::string_view s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string_view::npos) return {};
  const auto b = s.find_last_not_of(" \t");
  return std::string(s.substr(a, b - a + 1));
}

}  // namespace

SetSelection SetSelection::parse(std::string_view raw, std::string_view option) {
  SetSelection s;
  s.text_ = trimmed(raw);
  s.option_ = std::string(option);
  const auto fail = [&](const std::string& why) -> Error {
    return bad_input(fmt::format("{} '{}' is not valid: {}; {}", option, s.text_, why, kSyntax));
  };
  const auto number = [&](std::string_view part) {
    const std::string t = trimmed(part);
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc() || end != t.data() + t.size()) throw fail(fmt::format("'{}' is not a set number", t));
    return v;
  };
  if (s.text_.empty()) throw fail("it is empty");
  if (const auto colon = s.text_.find(':'); colon != std::string::npos) {
    const std::string a = trimmed(std::string_view(s.text_).substr(0, colon));
    const std::string b = trimmed(std::string_view(s.text_).substr(colon + 1));
    s.kind_ = Kind::range;
    s.first_ = a.empty() ? 0 : number(a);
    s.open_end_ = b.empty();
    s.end_ = b.empty() ? 0 : number(b);
    if (!s.open_end_ && s.end_ <= s.first_) throw fail("the range is empty (A:B holds sets A to B-1)");
    return s;
  }
  if (s.text_.find_first_of(",-") == std::string::npos) {
    s.kind_ = Kind::count;
    s.first_ = number(s.text_);
    if (s.first_ == 0) throw fail("0 sets chosen");
    return s;
  }
  s.kind_ = Kind::list;
  std::size_t start = 0;
  while (start <= s.text_.size()) {
    const auto comma = s.text_.find(',', start);
    const std::string_view item =
        std::string_view(s.text_).substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (trimmed(item).empty()) throw fail("an empty item in the list");
    const auto dash = item.find('-');
    const std::uint64_t first = number(item.substr(0, dash));
    const std::uint64_t last = dash == std::string_view::npos ? first : number(item.substr(dash + 1));
    if (last < first) throw fail(fmt::format("'{}' runs backwards", trimmed(item)));
    for (std::uint64_t k = first; k <= last; ++k) s.list_.push_back(k);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  std::sort(s.list_.begin(), s.list_.end());
  s.list_.erase(std::unique(s.list_.begin(), s.list_.end()), s.list_.end());
  return s;
}

std::vector<std::uint64_t> SetSelection::indices(std::uint64_t set_count) const {
  std::vector<std::uint64_t> out;
  if (kind_ == Kind::list) {
    if (!list_.empty() && list_.back() >= set_count)
      throw bad_input(fmt::format("{} '{}': set {} is past the end: the session holds {} sets (0 to {})", option_, text_,
                                  list_.back(), set_count, set_count == 0 ? 0 : set_count - 1));
    return list_;
  }
  const auto [first, end] = range(set_count);
  out.reserve(end - first);
  for (std::uint64_t k = first; k < end; ++k) out.push_back(k);
  return out;
}

std::pair<std::uint64_t, std::uint64_t> SetSelection::range(std::uint64_t set_count) const {
  const auto past_end = [&](std::uint64_t asked) {
    return bad_input(fmt::format("{} '{}' asks for sets up to {} but the session holds {} sets (0 to {})", option_,
                                 text_, asked - 1, set_count, set_count == 0 ? 0 : set_count - 1));
  };
  switch (kind_) {
    case Kind::all:
      return {0, set_count};
    case Kind::count:
      if (first_ > set_count) throw past_end(first_);
      return {0, first_};
    case Kind::range: {
      const std::uint64_t end = open_end_ ? set_count : end_;
      if (end > set_count || first_ >= set_count) throw past_end(std::max(end, first_ + 1));
      return {first_, end};
    }
    case Kind::list:
      break;
  }
  const std::vector<std::uint64_t> k = indices(set_count);
  if (k.back() - k.front() + 1 != k.size())
    throw bad_input(fmt::format("{} '{}': this command needs consecutive sets; write A:B (sets A to B-1)", option_,
                                text_));
  return {k.front(), k.back() + 1};
}

std::uint64_t SetSelection::leading_count(std::string_view why) const {
  switch (kind_) {
    case Kind::all:
      return 0;
    case Kind::count:
      return first_;
    case Kind::range:
      if (first_ == 0 && !open_end_) return end_;
      if (first_ == 0) return 0;
      break;
    case Kind::list:
      if (list_.front() == 0 && list_.back() + 1 == list_.size()) return list_.size();
      break;
  }
  throw bad_input(fmt::format("{} '{}' is not possible here: {}; write N or 0:N for the first N sets", option_, text_,
                              why));
}

}  // namespace tomorig
