#pragma once
// Value rules for TableReader: each returns nothing if the value is allowed, else the
// complaint that follows the value in the message ("-1 must be > 0"), so that every message
// says what is allowed.
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace tomorig::config::detail {

// A struct rather than a bare std::function so that a Rule<int> cannot silently convert to a
// Rule<double> (greater_than(0) on a double field would truncate the value first).
template <typename T>
struct Rule {
  std::function<std::optional<std::string>(const T&)> check;
  explicit operator bool() const { return static_cast<bool>(check); }
  std::optional<std::string> operator()(const T& v) const { return check(v); }
};

template <typename T>
Rule<T> greater_than(T low) {
  return {[low](const T& v) -> std::optional<std::string> {
    if (v > low) return std::nullopt;
    return fmt::format("must be > {}", low);
  }};
}

template <typename T>
Rule<T> at_least(T low) {
  return {[low](const T& v) -> std::optional<std::string> {
    if (v >= low) return std::nullopt;
    return fmt::format("must be >= {}", low);
  }};
}

// low < v <= high, e.g. particle images per pixel in (0, 1].
template <typename T>
Rule<T> in_left_open(T low, T high) {
  return {[low, high](const T& v) -> std::optional<std::string> {
    if (v > low && v <= high) return std::nullopt;
    return fmt::format("must be in ({}, {}]", low, high);
  }};
}

template <typename T>
Rule<T> in_closed(T low, T high) {
  return {[low, high](const T& v) -> std::optional<std::string> {
    if (v >= low && v <= high) return std::nullopt;
    return fmt::format("must be in [{}, {}]", low, high);
  }};
}

template <typename T>
Rule<T> one_of(std::vector<T> allowed) {
  return {[allowed = std::move(allowed)](const T& v) -> std::optional<std::string> {
    for (const auto& a : allowed)
      if (a == v) return std::nullopt;
    return fmt::format("must be one of {}", fmt::join(allowed, ", "));
  }};
}

// `rule`, then v <= high; `why` (if any) says where the ceiling comes from.
template <typename T>
Rule<T> and_at_most(Rule<T> rule, T high, std::string why = {}) {
  return {[rule = std::move(rule), high, why = std::move(why)](const T& v) -> std::optional<std::string> {
    if (auto complaint = rule(v)) return complaint;
    if (v <= high) return std::nullopt;
    // Large ceilings read better as 1e+09 than as 1000000000.
    std::string ceiling;
    if constexpr (std::is_floating_point_v<T>) ceiling = fmt::format("{:g}", high);
    else ceiling = fmt::format("{}", high);
    return why.empty() ? "must be <= " + ceiling : fmt::format("must be <= {} ({})", ceiling, why);
  }};
}

inline Rule<std::string> not_empty() {
  return {[](const std::string& v) -> std::optional<std::string> {
    if (!v.empty()) return std::nullopt;
    return std::string("must not be empty");
  }};
}

}  // namespace tomorig::config::detail
