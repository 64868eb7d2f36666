#include "plots.hpp"

#include <spdlog/spdlog.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace celc::app {
namespace {

// TEXT as one word for /bin/sh.
std::string shellQuote(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The last non-empty line of TEXT.
std::string lastLine(const std::string& text) {
  const std::size_t end = text.find_last_not_of("\r\n \t");
  if (end == std::string::npos) return {};
  const std::size_t nl = text.find_last_of('\n', end);
  const std::size_t start = nl == std::string::npos ? 0 : nl + 1;
  return text.substr(start, end + 1 - start);
}

}  // namespace

std::string findPlotScript(const std::string& name) {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("CELC_SCRIPTS_DIR")) candidates.emplace_back(env);
  candidates.emplace_back(CELC_SCRIPTS_DIR);
  candidates.emplace_back(fs::path("scripts"));
  for (const auto& dir : candidates) {
    const fs::path p = dir / name;
    if (fs::exists(p)) return p.string();
  }
  return {};
}

std::string runPlotScript(const std::string& name, const std::vector<std::string>& args) {
  const std::string script = findPlotScript(name);
  if (script.empty()) return "plot script scripts/" + name + " not found (set CELC_SCRIPTS_DIR)";
  std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  if (const char* env = std::getenv("CELC_PYTHON"); env && *env) python = env;
  std::string cmd = shellQuote(python) + " " + shellQuote(script);
  for (const auto& a : args) cmd += " " + shellQuote(a);
  spdlog::debug("plotting: {}", cmd);
  // The script's output (its one-line error) goes into the message, not the console.
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return "cannot start " + python;
  std::string out;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int status = pclose(p);
  if (status == 0) return {};
  const std::string why = lastLine(out);
  return name + " failed" + (why.empty() ? std::string(" (needs python3-matplotlib)") : ": " + why);
}

bool automaticPlots(bool no_plots_flag) {
  if (no_plots_flag) return false;
  const char* env = std::getenv("CELC_NO_PLOTS");
  return !(env && *env && std::string(env) != "0");
}

void plotRun(const std::string& outdir) {
  const std::string error = runPlotScript("plot_run.py", {outdir});
  if (!error.empty())
    spdlog::warn("no plots of {}: {}", outdir, error);
  else if (fs::exists(fs::path(outdir) / "error.png"))
    spdlog::info("plots: {}/velocity.png, error.png", outdir);
  else
    spdlog::info("plots: {}/velocity.png (no ground truth: no error.png)", outdir);
}

}  // namespace celc::app
