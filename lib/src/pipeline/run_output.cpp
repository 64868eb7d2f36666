#include "celc/pipeline/run_output.hpp"

#include <cmath>
#include <iomanip>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>
#include <stdexcept>

#include "celc/io/labelled_events.hpp"

namespace fs = std::filesystem;

namespace celc {

std::vector<std::string> windowsCsvLines(const WindowRecord& rec) {
  std::vector<std::string> lines;
  for (const MethodRow& row : rec.rows) {
    std::ostringstream o;
    o.precision(9);
    o << rec.index << "," << std::fixed << std::setprecision(6) << rec.t0 << "," << rec.t1 << ","
      << rec.n_events << "," << rec.n_clusters << "," << toString(row.method) << ",";
    o << (rec.window_status.empty() ? toString(row.result.status) : rec.window_status) << ",";
    o << std::setprecision(9);
    if (row.result.ok()) o << row.result.v.x() << "," << row.result.v.y() << "," << row.result.v.z();
    else o << ",,";
    o << ",";
    if (rec.has_gt) o << rec.gt.x() << "," << rec.gt.y() << "," << rec.gt.z();
    else o << ",,";
    o << ",";
    if (row.has_metrics) o << row.eps << "," << row.phi;
    else o << ",";
    o << "," << std::setprecision(3) << row.result.time_us * 1e-3;
    lines.push_back(o.str());
  }
  return lines;
}

RunOutput::RunOutput(const std::string& dir, OutputMode mode, std::size_t methods_per_window)
    : dir_(dir), csv_path_((fs::path(dir) / "windows.csv").string()) {
  const bool has_run = fs::exists(csv_path_);
  if (has_run && mode == OutputMode::Create)
    throw std::runtime_error(dir + ": holds an earlier run (windows.csv); use --force to replace it or --resume to continue it");
  fs::create_directories(dir);
  if (mode == OutputMode::Resume && has_run) {
    // Keep the complete windows only (all methods' rows present).
    const auto rows = readWindowsCsv(csv_path_, true);
    std::map<std::int64_t, std::size_t> count;
    for (const auto& r : rows) count[r.window]++;
    for (const auto& [w, n] : count) {
      if (n != methods_per_window) break;
      resume_after_ = w;
    }
    std::ifstream in(csv_path_);
    std::string content = windowsCsvHeader() + "\n", line;
    std::getline(in, line);  // header
    std::int64_t kept = 0;
    while (std::getline(in, line)) {
      const auto comma = line.find(',');
      if (comma == std::string::npos) break;
      std::int64_t w = -1;
      try {
        w = std::stoll(line.substr(0, comma));
      } catch (const std::exception&) {
        break;
      }
      if (w > resume_after_) break;
      content += line + "\n";
      ++kept;
    }
    (void)kept;
    writeFileAtomically(csv_path_, content);
    csv_.open(csv_path_, std::ios::app);
  } else {
    csv_.open(csv_path_, std::ios::trunc);
    csv_ << windowsCsvHeader() << "\n";
    csv_.flush();
  }
  if (!csv_) throw std::runtime_error(csv_path_ + ": cannot write");
}

void RunOutput::append(const WindowRecord& record) {
  std::string block;
  for (const auto& l : windowsCsvLines(record)) block += l + "\n";
  csv_ << block;
  csv_.flush();  // a finished window survives an interruption
  if (!csv_) throw std::runtime_error(csv_path_ + ": write failed");
}

void RunOutput::writeConfig(const std::string& yaml) const {
  writeFileAtomically((fs::path(dir_) / "config.yaml").string(), yaml);
}

std::vector<MethodSummary> RunOutput::writeSummary(const std::string& title,
                                                         const std::vector<std::string>& notes) const {
  const auto summaries = summarize(readWindowsCsv(csv_path_, true));
  writeFileAtomically((fs::path(dir_) / "summary.md").string(),
                      summaryMarkdown(title, summaries, notes));
  return summaries;
}

std::pair<int, int> parseShard(const std::string& text) {
  const auto slash = text.find('/');
  int k = 0, n = 0;
  try {
    if (slash == std::string::npos) throw std::invalid_argument(text);
    size_t a = 0, b = 0;
    k = std::stoi(text.substr(0, slash), &a);
    n = std::stoi(text.substr(slash + 1), &b);
    if (a != slash || b != text.size() - slash - 1) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw std::invalid_argument("--shard '" + text + "': expected K/N, e.g. 2/8");
  }
  if (n < 1 || k < 1 || k > n)
    throw std::invalid_argument("--shard '" + text + "': need 1 <= K <= N");
  return {k - 1, n};
}

SequenceOutcome runSequence(const SequenceJob& job,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  SequenceOutcome out;
  SequenceRunner runner(job.inputs, job.config);
  RunOutput output(job.outdir, job.mode, job.config.methods.size());
  output.writeConfig(toYaml(job.config));
  WindowFilter filter;
  filter.after = output.resumeAfter();
  filter.shard_index = job.shard_index;
  filter.shard_count = job.shard_count;
  out.stats = runner.run(job.threads, filter, [&](const WindowRecord& r) { output.append(r); }, progress);

  out.notes = runner.describe();
  if (job.shard_count > 1)
    out.notes.push_back("shard " + std::to_string(job.shard_index + 1) + "/" + std::to_string(job.shard_count));
  if (filter.after >= 0) out.notes.push_back("resumed after window " + std::to_string(filter.after));
  const RunStats& s = out.stats;
  std::ostringstream t;
  t.precision(3);
  t << s.windows_processed << " windows processed of " << s.windows_read << " read, "
    << s.events_processed << " events in " << s.seconds_total << " s ("
    << (s.seconds_total > 0 ? s.events_processed / s.seconds_total / 1e6 : 0.0) << " M events/s)";
  out.notes.push_back(t.str());
  const double busy = s.seconds_reading + s.stage_seconds.cluster + s.stage_seconds.lines +
                      s.stage_seconds.solve + s.stage_seconds.groundtruth;
  if (busy > 0) {
    std::ostringstream sh;
    sh.precision(3);
    sh << "time per stage (share of summed stage time): reading " << 100 * s.seconds_reading / busy
       << "%, clustering " << 100 * s.stage_seconds.cluster / busy << "%, undistortion+lines "
       << 100 * s.stage_seconds.lines / busy << "%, solvers " << 100 * s.stage_seconds.solve / busy
       << "%, ground truth " << 100 * s.stage_seconds.groundtruth / busy << "%";
    out.notes.push_back(sh.str());
  }
  if (s.reader_warnings > 0)
    out.notes.push_back(std::to_string(s.reader_warnings) + " reader warnings (see celc info)");
  out.summaries = output.writeSummary(job.title, out.notes);
  return out;
}

}  // namespace celc
