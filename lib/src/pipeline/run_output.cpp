#include "celc/pipeline/run_output.hpp"

#include <cmath>
#include <ctime>
#include <iomanip>
#include <iterator>
#include <set>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>
#include <stdexcept>

#include "celc/io/labelled_events.hpp"

namespace fs = std::filesystem;

namespace celc {
namespace {

// What is made from the finished rows: summary.md and the plots of `celc run`.
void removeResultFiles(const std::string& dir) {
  for (const char* f : {"summary.md", "velocity.png", "error.png"}) fs::remove(fs::path(dir) / f);
}

}  // namespace

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
    // Quality columns: reason,sigma_deg,parallax,n_lines,wx,wy,wz,translation_px.
    const SolverResult& r = row.result;
    std::string reason;
    if (!rec.window_status.empty()) reason = rec.window_status;
    else if (r.status == SolveStatus::Degenerate) reason = toString(r.degeneracy);
    else if (!r.ok()) reason = toString(r.status);
    o << "," << reason << ",";
    if (row.result.ok() && !std::isnan(r.sigma_deg))
      o << std::setprecision(4) << r.sigma_deg;  // "inf": unobservable at the estimate
    o << ",";
    const bool solved = rec.window_status.empty();
    if (solved && std::isfinite(r.parallax)) o << std::setprecision(4) << r.parallax;
    o << ",";
    if (solved) o << r.n_lines;
    o << std::setprecision(6) << std::fixed;
    if (rec.has_omega) o << "," << rec.omega.x() << "," << rec.omega.y() << "," << rec.omega.z();
    else o << ",,,";
    o << ",";
    if (std::isfinite(rec.translation_px)) o << std::setprecision(2) << rec.translation_px;
    // Truth columns: purity,impure_clusters,edges,edges_complete,coverage,noise_admitted,oracle_phi.
    o << ",";
    if (rec.has_truth) {
      const ClusterQuality& q = rec.quality;
      const auto share = [&](double x) {
        if (std::isfinite(x)) o << std::setprecision(4) << x;
      };
      share(q.purity);
      o << "," << q.n_impure << "," << q.n_edges << "," << q.n_edges_complete << ",";
      share(q.coverage);
      o << ",";
      share(q.noise_admitted);
      o << ",";
      if (std::isfinite(rec.oracle_phi)) o << std::setprecision(9) << rec.oracle_phi;
    } else {
      o << ",,,,,,";
    }
    // sigma_deg's parts: sigma_fisher_deg,sigma_budget_deg,sigma_rule.
    o << ",";
    if (r.ok() && !std::isnan(r.sigma_fisher_deg)) o << std::setprecision(4) << r.sigma_fisher_deg;
    o << ",";
    if (r.ok() && !std::isnan(r.sigma_budget_deg)) o << std::setprecision(4) << r.sigma_budget_deg;
    o << "," << (r.ok() ? r.sigma_rule : std::string());
    // The motion model columns: model,ax,ay,az (celc_acc only).
    o << ",";
    if (row.method == Method::CelcAcc && r.ok()) o << (r.acceleration_seen ? "acceleration" : "constant_velocity");
    if (row.method == Method::CelcAcc && r.ok() && r.acceleration.allFinite())
      o << std::setprecision(6) << "," << r.acceleration.x() << "," << r.acceleration.y() << ","
        << r.acceleration.z();
    else
      o << ",,,";
    lines.push_back(o.str());
  }
  return lines;
}

bool isIncompleteRun(const std::string& dir, std::string* reason) {
  const fs::path marker = fs::path(dir) / kIncompleteMarker;
  if (!fs::exists(marker)) return false;
  if (reason) {
    std::ifstream in(marker);
    std::getline(in, *reason);
  }
  return true;
}

namespace {

// windows.csv holds at least one row after its header (a header-only file,
// from a run that stopped before its first window, is not a run).
bool holdsRows(const std::string& csv_path) {
  std::ifstream in(csv_path);
  if (!in) return false;
  std::string line;
  if (!std::getline(in, line)) return false;
  while (std::getline(in, line))
    if (!line.empty() && line != "\r") return true;
  return false;
}

std::string nowText() {
  const std::time_t t = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", std::localtime(&t));
  return buf;
}

}  // namespace

std::string inputIdentity(const RunInputs& inputs) {
  std::string out;
  const std::pair<const char*, std::string> files[] = {{"events", inputs.events},
                                                       {"calibration", inputs.calib},
                                                       {"ground truth", inputs.groundtruth},
                                                       {"imu", inputs.imu}};
  for (const auto& [what, path] : files) {
    if (path.empty()) continue;
    std::error_code ec;
    out += std::string(what) + ": " + fs::absolute(path, ec).lexically_normal().string() + "\n";
  }
  return out;
}

RunOutput::RunOutput(const std::string& dir, OutputMode mode, const RunConfig& config, const std::string& inputs)
    : dir_(dir), csv_path_((fs::path(dir) / "windows.csv").string()) {
  const fs::path config_path = fs::path(dir) / "config.yaml";
  const fs::path input_path = fs::path(dir) / "input.txt";
  const bool has_run = holdsRows(csv_path_);
  if (has_run && mode == OutputMode::Create)
    throw std::runtime_error(dir + ": holds an earlier run (windows.csv); use --force to replace it or --resume to continue it");
  bool resume = has_run && (mode == OutputMode::Resume || mode == OutputMode::ResumeOrReplace);
  if (resume) {
    // Continue only what the stored configuration describes.
    std::string difference;
    if (!fs::exists(config_path)) {
      difference = "missing, so the configuration of the rows is unknown";
    } else {
      try {
        difference = firstConfigDifference(loadRunConfig(config_path.string()), config);
        if (!difference.empty()) difference = "differs from this run's configuration at " + difference + " (stored vs now)";
      } catch (const std::exception& e) {
        difference = std::string("unreadable (") + e.what() + ")";
      }
    }
    if (!difference.empty()) {
      if (mode == OutputMode::Resume)
        throw std::runtime_error(config_path.string() + ": " + difference +
                                 "; --resume continues the same configuration only (--resume --force replaces the run)");
      notes_.push_back("replaced the earlier run: its config.yaml " + difference);
      resume = false;
    }
  }
  if (resume && !inputs.empty() && fs::exists(input_path)) {
    // Rows of another recording are not continued either.
    std::ifstream in(input_path);
    const std::string stored((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (stored != inputs) {
      const auto firstLine = [](const std::string& text) { return text.substr(0, text.find('\n')); };
      const std::string difference = "holds a run of other inputs (stored: " + firstLine(stored) +
                                     "; now: " + firstLine(inputs) + ")";
      if (mode == OutputMode::Resume)
        throw std::runtime_error(input_path.string() + ": " + difference +
                                 "; --resume continues the same recording only (--resume --force replaces the run)");
      notes_.push_back("replaced the earlier run: its input.txt " + difference);
      resume = false;
    }
  }
  created_dir_ = !fs::exists(dir);
  fs::create_directories(dir);
  if (resume) {
    // Keep the complete windows only (all methods' rows present); rows beyond
    // the last complete window may only be the torn last window.
    const auto rows = readWindowsCsv(csv_path_, true);
    std::map<std::int64_t, std::set<std::string>> methods_of;
    for (const auto& r : rows) methods_of[r.window].insert(r.method);
    std::set<std::string> wanted;
    for (Method m : config.methods) wanted.insert(toString(m));
    std::int64_t incomplete = -1;
    for (const auto& [w, names] : methods_of) {
      if (incomplete >= 0)
        throw std::runtime_error(csv_path_ + ": window " + std::to_string(incomplete) +
                                 " lacks rows of some methods but later windows follow; not resumable "
                                 "(--force replaces the run)");
      if (names == wanted) resume_after_ = w;
      else incomplete = w;
    }
    std::ifstream in(csv_path_);
    std::string content = windowsCsvHeader() + "\n", line;
    std::getline(in, line);  // header
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
      content += padWindowsCsvLine(line) + "\n";
    }
    in.close();
    writeMarker("celc run resumed " + nowText() + "; not complete (interrupted, or stopped on an error)");
    removeResultFiles(dir);
    writeFileAtomically(csv_path_, content);
    csv_.open(csv_path_, std::ios::app);
  } else {
    // The old summary and plots go first: they never stand beside new rows.
    removeResultFiles(dir);
    writeMarker("celc run started " + nowText() + "; not complete (interrupted, or stopped on an error)");
    csv_.open(csv_path_, std::ios::trunc);
    csv_ << windowsCsvHeader() << "\n";
    csv_.flush();
  }
  if (!csv_) throw std::runtime_error(csv_path_ + ": cannot write");
  writeFileAtomically(config_path.string(), toYaml(config));
  if (!inputs.empty()) writeFileAtomically(input_path.string(), inputs);
}

void RunOutput::writeMarker(const std::string& text) const {
  writeFileAtomically((fs::path(dir_) / kIncompleteMarker).string(),
                      text + "\n\nThis folder is not a complete result: `celc table` refuses it. "
                             "Continue the run with `celc run ... --resume`, or replace it with --force.\n");
}

void RunOutput::append(const WindowRecord& record) {
  std::string block;
  for (const auto& l : windowsCsvLines(record)) block += l + "\n";
  csv_ << block;
  csv_.flush();  // a finished window survives an interruption
  if (!csv_) throw std::runtime_error(csv_path_ + ": write failed");
  ++appended_;
}

std::vector<MethodSummary> RunOutput::writeSummary(const std::string& title,
                                                         const std::vector<std::string>& notes) const {
  const std::vector<WindowsCsvRow> rows = readWindowsCsv(csv_path_, true);
  const auto summaries = summarize(rows);
  std::string text = summaryMarkdown(title, summaries, notes);
  if (const std::string truth = truthSummaryMarkdown(rows); !truth.empty()) {
    while (!text.empty() && text.back() == '\n') text.pop_back();
    text += "\n\n" + truth;
  }
  writeFileAtomically((fs::path(dir_) / "summary.md").string(), text);
  return summaries;
}

void RunOutput::complete() {
  csv_.close();
  fs::remove(fs::path(dir_) / kIncompleteMarker);
}

void RunOutput::abandon(const std::string& error) {
  csv_.close();
  std::error_code ec;
  if (appended_ == 0 && resume_after_ < 0) {
    // Nothing of a result: remove what this run created.
    for (const char* f : {"windows.csv", "config.yaml", "input.txt", "summary.md", kIncompleteMarker})
      fs::remove(fs::path(dir_) / f, ec);
    if (created_dir_ && fs::is_empty(dir_, ec)) fs::remove(dir_, ec);
    return;
  }
  std::string line = error;
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  try {
    writeMarker("celc run stopped on an error " + nowText() + ": " + line);
  } catch (const std::exception&) {
    // the marker of the start stays
  }
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

namespace {
void runInto(SequenceRunner& runner, RunOutput& output, const SequenceJob& job,
             const std::function<void(std::uint64_t, std::uint64_t)>& progress, SequenceOutcome& out);
}  // namespace

SequenceOutcome runSequence(const SequenceJob& job,
                            const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  SequenceOutcome out;
  SequenceRunner runner(job.inputs, job.config);  // opens the inputs: nothing written yet
  RunOutput output(job.outdir, job.mode, job.config, inputIdentity(job.inputs));
  if (!job.dump_windows.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(job.dump_windows, ec);
    if (ec) throw std::runtime_error(job.dump_windows + ": cannot create the folder (" + ec.message() + ")");
    WindowDumpContext context;
    context.dir = std::filesystem::absolute(job.dump_windows).string();  // the commands run from any folder
    context.program = job.dump_program;
    context.config = std::filesystem::absolute(std::filesystem::path(job.outdir) / "config.yaml").string();
    runner.dumpWindows(context);
  }
  try {
    runInto(runner, output, job, progress, out);
  } catch (const std::exception& e) {
    output.abandon(e.what());
    throw;
  }
  output.complete();
  return out;
}

namespace {
void runInto(SequenceRunner& runner, RunOutput& output, const SequenceJob& job,
             const std::function<void(std::uint64_t, std::uint64_t)>& progress, SequenceOutcome& out) {
  WindowFilter filter;
  filter.after = output.resumeAfter();
  filter.shard_index = job.shard_index;
  filter.shard_count = job.shard_count;
  out.stats = runner.run(job.threads, filter, [&](const WindowRecord& r) { output.append(r); }, progress);

  out.notes = runner.describe();
  out.notes.insert(out.notes.end(), output.notes().begin(), output.notes().end());
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
                      s.stage_seconds.solve + s.stage_seconds.redraw + s.stage_seconds.groundtruth +
                      s.stage_seconds.truth;
  if (busy > 0) {
    std::ostringstream sh;
    sh.precision(3);
    sh << "time per stage (share of summed stage time): reading " << 100 * s.seconds_reading / busy
       << "%, clustering " << 100 * s.stage_seconds.cluster / busy << "%, undistortion+lines "
       << 100 * s.stage_seconds.lines / busy << "%, solvers " << 100 * s.stage_seconds.solve / busy
       << "%, clusters redrawn under the motion and solved again " << 100 * s.stage_seconds.redraw / busy
       << "%, ground truth " << 100 * s.stage_seconds.groundtruth / busy << "%";
    if (s.stage_seconds.truth > 0)
      sh << ", clusters against the truth labels and the oracle " << 100 * s.stage_seconds.truth / busy << "%";
    out.notes.push_back(sh.str());
  }
  if (s.reader_warnings > 0)
    out.notes.push_back(std::to_string(s.reader_warnings) + " reader warnings (see celc info)");
  if (const RunClusterTotals& c = s.clustering; c.events() > 0) {
    const double n = static_cast<double>(c.events());
    std::ostringstream cl;
    cl.precision(3);
    cl << "events in a cluster: " << 100 * c.clustered / n << "% of the clustered windows' events; left out: ";
    const std::pair<std::uint64_t, const char*> parts[] = {
        {c.no_region, "in no region"},
        {c.small_region, "in regions under cluster.min_cluster_size"},
        {c.failed_checks, "failing the checks"},
        {c.off_planes, "off the planes"},
        {c.off_moving_lines, "off the moving lines"},
        {c.invalid, "invalid"}};
    bool first = true;
    for (const auto& [count, what] : parts) {
      if (count == 0) continue;
      cl << (first ? "" : ", ") << 100 * count / n << "% " << what;
      first = false;
    }
    if (first) cl << "none";
    cl << " (docs/clustering.md)";
    out.notes.push_back(cl.str());
  }
  if (s.clusters_line_fit_failed > 0)
    out.notes.push_back(std::to_string(s.clusters_line_fit_failed) +
                        " clusters whose start / end lines could not be fitted: used by npt only "
                        "(reasons with --verbose)");
  const WindowTail& tail = s.tail;
  if (tail.events > 0) {
    std::ostringstream n;
    n.precision(3);
    n << "last, partial window: " << tail.events << " events, " << 100 * tail.share << "% of a window, "
      << (tail.emitted ? "processed" : "not processed") << " (windows.partial_min_share = "
      << job.config.windows.partial_min_share << (job.config.windows.keep_partial ? ", keep_partial" : "") << ")";
    out.notes.push_back(n.str());
  }
  out.summaries = output.writeSummary(job.title, out.notes);
}
}  // namespace

}  // namespace celc
