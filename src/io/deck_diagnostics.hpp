// Deck diagnostics: every message the deck reader gives, each with its location (deck.hpp
// lists the forms). Internal to the deck reader (deck.cpp, deck_reader.cpp, deck_set.cpp,
// placement.cpp): nothing throws while a deck is read; every message goes to one Diagnostics,
// and the reader throws one InputError holding them all at the end.
#pragma once

#include <toml++/toml.h>

#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

namespace dem2d::deck {

// The nodes that --set overrides made, with the option's text ("--set drum.speed=2").
using Origins = std::unordered_map<const toml::node*, std::string>;

class Diagnostics {
 public:
  Diagnostics(std::string file, const Origins& origins)
      : file_(std::move(file)), origins_(origins) {}

  void set_root(const toml::table* root) { root_ = root; }
  // The deck's text, so that messages show a value as the user wrote it ("2.0e11").
  void set_source(std::string_view text);

  // A value as the deck wrote it when it is on one line there, else formatted.
  std::string shown(const toml::node& node) const;

  // Where a value came from: the --set option that made it, else its deck position.
  std::string where(const toml::node& node) const { return location(node); }
  // At a value or table: the --set option that made it, else its deck position, else the file.
  void error_at(const toml::node& node, std::string_view message) { add(location(node), message); }
  // At a key: the key's own position when it is in the deck.
  void error_at_key(const toml::key& key, const toml::node& value, std::string_view message);
  void error(std::string_view message) { add(file_, message); }
  void error_in(std::string_view where, std::string_view message) { add(where, message); }
  void add(std::string complete_message) { messages_.push_back(std::move(complete_message)); }

  std::vector<std::string>& messages() { return messages_; }

 private:
  std::string position(const toml::source_position& at) const;
  std::string location(const toml::node& node) const;
  void add(std::string_view where, std::string_view message);

  std::string file_;
  const Origins& origins_;
  const toml::table* root_ = nullptr;
  std::vector<std::string> messages_;
  std::vector<std::string_view> lines_;
};

}  // namespace dem2d::deck
