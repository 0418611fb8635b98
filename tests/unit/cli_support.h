// Running the motes command from tests: shared by the CLI tests (tests/unit/test_cli.cpp) and the
// render CLI tests (tests/render/test_render_cli.cpp).
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "unit/test_support.h"

namespace motes_test {

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// s in single quotes for the shell.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct Outcome {
  int exit_code = -1;
  std::string out, err;
};

/// Runs `ENV motes ARGS` (ENV: "VAR=value ..." or empty) with stdout and stderr captured; a run
/// that hangs is killed after timeout_s seconds.
inline Outcome run_motes(const TempDir& tmp, const std::vector<std::string>& args,
                         const std::string& env = "", int timeout_s = 120) {
  std::string cmd;
  if (!env.empty()) cmd.append("env ").append(env).append(" ");
  cmd.append("timeout ")
      .append(std::to_string(timeout_s))
      .append(" ")
      .append(quote(MOTES_CLI_PATH));
  for (const std::string& a : args) cmd.append(" ").append(quote(a));
  const std::string out = tmp / "stdout.txt", err = tmp / "stderr.txt";
  cmd.append(" >").append(quote(out)).append(" 2>").append(quote(err)).append(" </dev/null");
  const int status = std::system(cmd.c_str());
  Outcome o;
  o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = read_text(out);
  o.err = read_text(err);
  return o;
}

inline std::string describe(const Outcome& o) {
  return "exit " + std::to_string(o.exit_code) + "\n--- stdout\n" + o.out + "--- stderr\n" + o.err;
}

inline bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace motes_test
