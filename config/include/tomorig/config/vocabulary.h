#pragma once
// The rig file's closed vocabularies: each enum of the configuration has one table of the
// words that spell its values in TOML (rig_vocabulary.h), and this one parse/print pair reads
// and writes every one of them. The decoder reads through the same table, so a word the
// decoder accepts, the word a message prints and the word `tomorig config` writes are one.
#include <optional>
#include <string>
#include <string_view>

namespace tomorig::config {

template <typename E>
struct Word {
  std::string_view name;  // as written in the rig file
  E value;
};

// Specialised once per enum, next to the enum:
//   template <> struct Vocabulary<E> { static constexpr Word<E> words[] = {...}; };
template <typename E>
struct Vocabulary;

template <typename E>
concept HasVocabulary = requires { Vocabulary<E>::words; };

// The value `text` names, or nothing (exact, case-sensitive: TOML strings are).
template <HasVocabulary E>
std::optional<E> parse(std::string_view text) {
  for (const auto& w : Vocabulary<E>::words)
    if (w.name == text) return w.value;
  return std::nullopt;
}

// The word for `value`; "unknown" for a value the rig file cannot spell (e.g.
// LightSourceKind::unknown, a kind not stated).
template <HasVocabulary E>
std::string_view to_string(E value) {
  for (const auto& w : Vocabulary<E>::words)
    if (w.value == value) return w.name;
  return "unknown";
}

// "first, second, both": the allowed words, for messages.
template <HasVocabulary E>
std::string allowed_words() {
  std::string out;
  for (const auto& w : Vocabulary<E>::words) {
    if (!out.empty()) out += ", ";
    out += w.name;
  }
  return out;
}

}  // namespace tomorig::config
