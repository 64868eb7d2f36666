#pragma once
// Helpers for tests that run the `celc` executable.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace celc::test {

struct CliRun {
  int status = -1;
  std::string out;  ///< stdout
  std::string err;  ///< stderr
};

inline std::string readAll(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs a shell command, capturing its stdout (err stays empty) and exit status.
inline CliRun runShell(const std::string& command) {
  CliRun r;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  r.status = WEXITSTATUS(pclose(p));
  return r;
}

/// Runs `celc ARGS`, capturing stdout and (through DIR/stderr.txt) stderr.
/// Without `plots` the automatic plots (python3-matplotlib, seconds per run)
/// are off (CELC_NO_PLOTS=1); tests of the plots pass plots = true.
inline CliRun runCelc(const std::string& args, const std::filesystem::path& dir, bool plots = false) {
  const std::filesystem::path err = dir / "stderr.txt";
  const std::string cmd = std::string(plots ? "" : "CELC_NO_PLOTS=1 ") + CELC_BINARY + " " + args + " 2> '" +
                          err.string() + "'";
  CliRun r = runShell(cmd);
  r.err = readAll(err);
  return r;
}

/// A fresh, empty temporary folder unique to this process.
inline std::filesystem::path freshTempDir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() /
                 ("celc_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace celc::test
