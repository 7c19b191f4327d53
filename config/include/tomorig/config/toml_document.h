#pragma once
// A parsed TOML document for the readers of tomorig's other TOML files (calibration files,
// optics set-ups, preprocessing chains), so that config/ is the only module that links the TOML
// parser. Each reader keeps its own schema and messages; this is only the tree: tables, arrays,
// values and the line each came from.
//
//   const TomlDocument doc = TomlDocument::parse(text, "chain.toml");   // throws TomlSyntaxError
//   for (const auto& [key, node] : doc.root().entries()) ...
//   if (const TomlNode steps = doc.root()["preprocess"]["steps"]; steps.is_array()) ...
//
// Values convert as toml++'s node::value() does: an integer reads as a float, a float without a
// fraction as an integer, a boolean as an integer and an integer as a boolean.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tomorig::config {

// A view of one node of a TomlDocument (which must outlive it); default-constructed: absent.
// Looking up a key or an index that is not there gives an absent node, never an error.
class TomlNode {
 public:
  TomlNode() = default;

  explicit operator bool() const { return node_ != nullptr; }
  bool is_table() const;
  bool is_array() const;
  bool is_array_of_tables() const;  // an array whose every element is a table
  bool is_number() const;           // an integer or a float
  bool is_integer() const;
  bool is_string() const;
  bool is_boolean() const;
  int line() const;  // where the node starts in the file (1-based); 0 for an absent node

  // Tables.
  TomlNode operator[](std::string_view key) const;
  bool contains(std::string_view key) const;
  std::vector<std::pair<std::string, TomlNode>> entries() const;  // in the order of the keys

  // Arrays.
  std::size_t size() const;  // elements of an array; 0 for anything else
  TomlNode operator[](std::size_t index) const;

  // Values (see the conversions above); nullopt for an absent node or one that does not convert.
  std::optional<double> as_double() const;
  std::optional<std::int64_t> as_integer() const;
  std::optional<bool> as_bool() const;
  std::optional<std::string> as_string() const;

 private:
  friend class TomlDocument;
  explicit TomlNode(const void* node) : node_(node) {}
  const void* node_ = nullptr;  // a toml::node of the document
};

// The file is not TOML: where, and what toml++ said.
class TomlSyntaxError : public std::runtime_error {
 public:
  TomlSyntaxError(int line, std::string description)
      : std::runtime_error(description), line_(line), description_(std::move(description)) {}
  int line() const { return line_; }
  const std::string& description() const { return description_; }

 private:
  int line_;
  std::string description_;
};

class TomlDocument {
 public:
  // `source` names the text in toml++'s own messages (a file name).
  static TomlDocument parse(std::string_view text, const std::string& source);
  // A file that cannot be opened is reported as a TomlSyntaxError too (line 0).
  static TomlDocument parse_file(const std::filesystem::path& path);

  TomlDocument(TomlDocument&&) noexcept;
  TomlDocument& operator=(TomlDocument&&) noexcept;
  ~TomlDocument();

  TomlNode root() const;

 private:
  struct Tree;
  explicit TomlDocument(std::unique_ptr<Tree> tree);
  std::unique_ptr<Tree> tree_;
};

}  // namespace tomorig::config
