#pragma once
// A Code_Aster command file (.comm) split into its calls, for the tests that check it against a
// keyword table taken from Code_Aster's command catalogues (test_fem.cpp, test_fem_plastic.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace impactdeck::test {

struct Call {
  std::string command;
  std::map<std::string, std::string> keys;  // top-level keyword -> raw value
  std::set<std::string> nested;             // keywords inside _F(...)
};

inline std::vector<std::string> split_top(const std::string& s) {
  std::vector<std::string> parts;
  int depth = 0;
  bool quote = false;
  std::string cur;
  for (char c : s) {
    if (c == '\'') quote = !quote;
    if (!quote && (c == '(')) ++depth;
    if (!quote && (c == ')')) --depth;
    if (!quote && depth == 0 && c == ',') {
      parts.push_back(cur);
      cur.clear();
      continue;
    }
    cur += c;
  }
  if (cur.find_first_not_of(" \n") != std::string::npos) parts.push_back(cur);
  return parts;
}

inline std::vector<Call> parse_comm(const std::string& text) {
  std::string code;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) code += l.substr(0, l.find('#')) + "\n";
  std::vector<Call> calls;
  const std::regex head(R"(^\s*(?:[A-Za-z_][A-Za-z0-9_]*\s*=\s*)?([A-Z_]+)\s*\()");
  std::size_t pos = 0;
  while (pos < code.size()) {
    std::smatch m;
    const std::string rest = code.substr(pos);
    if (!std::regex_search(rest, m, head)) break;
    const std::size_t open = pos + m.position(0) + m.length(0) - 1;
    int depth = 0;
    std::size_t close = open;
    for (; close < code.size(); ++close) {
      if (code[close] == '(') ++depth;
      if (code[close] == ')' && --depth == 0) break;
    }
    Call c;
    c.command = m[1];
    for (const std::string& part : split_top(code.substr(open + 1, close - open - 1))) {
      const auto eq = part.find('=');
      if (eq == std::string::npos) continue;
      std::string k = part.substr(0, eq);
      k.erase(0, k.find_first_not_of(" \n"));
      k.erase(k.find_last_not_of(" \n") + 1);
      const std::string v = part.substr(eq + 1);
      c.keys[k] = v;
      const std::regex nested_key(R"(([A-Z_]+)\s*=)");
      for (auto it = std::sregex_iterator(v.begin(), v.end(), nested_key); it != std::sregex_iterator(); ++it) {
        c.nested.insert((*it)[1]);
      }
    }
    calls.push_back(c);
    pos = close + 1;
  }
  return calls;
}

inline std::string strip(std::string v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](char ch) { return ch == ' ' || ch == '\n'; }), v.end());
  return v;
}

/// command -> (allowed top-level keywords, allowed keywords inside _F): a keyword table.
using KeywordTable = std::map<std::string, std::pair<std::set<std::string>, std::set<std::string>>>;

/// Checks every call of `calls` against `table` (each command known, each keyword allowed) and
/// that every command of the table is called; returns the first call of each command.
inline std::map<std::string, const Call*> check_keywords(const std::vector<Call>& calls, const KeywordTable& table) {
  std::map<std::string, const Call*> first;
  for (const Call& c : calls) {
    auto t = table.find(c.command);
    EXPECT_NE(t, table.end()) << "command not in the keyword table: " << c.command;
    if (t == table.end()) continue;
    for (const auto& [k, v] : c.keys) EXPECT_TRUE(t->second.first.count(k)) << c.command << " " << k;
    for (const auto& k : c.nested) {
      EXPECT_TRUE(t->second.first.count(k) || t->second.second.count(k)) << c.command << " _F " << k;
    }
    first.emplace(c.command, &c);
  }
  for (const auto& [cmd, spec] : table) EXPECT_TRUE(first.count(cmd)) << "missing " << cmd;
  return first;
}

}  // namespace impactdeck::test
