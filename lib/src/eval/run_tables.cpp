#include "celc/eval/run_tables.hpp"

#include "celc/core/text.hpp"
#include "celc/eval/metrics.hpp"
#include "celc/eval/statistics.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace celc {

std::string windowsCsvHeaderV1() {
  return "window,t_start,t_end,n_events,n_clusters,method,status,vx,vy,vz,gt_vx,gt_vy,gt_vz,eps,phi,runtime_ms";
}

std::string windowsCsvHeaderV2() { return windowsCsvHeaderV1() + ",reason,sigma_deg,parallax,n_lines,wx,wy,wz"; }
std::string windowsCsvHeaderV3() { return windowsCsvHeaderV2() + ",translation_px"; }
std::string windowsCsvHeaderV4() {
  return windowsCsvHeaderV3() + ",purity,impure_clusters,edges,edges_complete,coverage,noise_admitted,oracle_phi";
}
std::string windowsCsvHeaderV5() { return windowsCsvHeaderV4() + ",sigma_fisher_deg,sigma_budget_deg,sigma_rule"; }
std::string windowsCsvHeader() { return windowsCsvHeaderV5() + ",model,ax,ay,az"; }

std::string padWindowsCsvLine(const std::string& line) {
  std::string l = line;
  if (!l.empty() && l.back() == '\r') l.pop_back();
  const auto commas = std::count(l.begin(), l.end(), ',');
  if (l.empty() || (commas != 15 && commas != 22 && commas != 23 && commas != 30 && commas != 33)) return line;
  const std::string truth = ",,,,,,,";  // the seven truth columns
  const std::string parts = ",,,";      // sigma_deg's three parts
  const std::string model = ",,,,";     // model,ax,ay,az
  return l + (commas == 15   ? ",,,,,,,," + truth + parts + model
              : commas == 22 ? "," + truth + parts + model
              : commas == 23 ? truth + parts + model
              : commas == 30 ? parts + model
                             : model);
}

namespace {

double toDouble(const std::string& s, const std::string& where, const char* col) {
  double v = 0.0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty())
    throw std::runtime_error(where + ": column '" + col + "' is not a number: '" + s + "'");
  return v;
}



std::string fmt(double x, int digits = 4) {
  if (!std::isfinite(x)) return "-";
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << x;
  return os.str();
}

}  // namespace

std::vector<WindowsCsvRow> readWindowsCsv(const std::string& path, bool tolerate_truncated_tail) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const bool complete_last = !content.empty() && content.back() == '\n';
  std::stringstream ss(content);
  std::string line;
  std::vector<WindowsCsvRow> rows;
  size_t no = 0;
  std::vector<std::string> lines;
  while (std::getline(ss, line)) lines.push_back(line);
  for (size_t i = 0; i < lines.size(); ++i) {
    no = i + 1;
    std::string l = lines[i];
    if (!l.empty() && l.back() == '\r') l.pop_back();
    const std::string where = path + ":" + std::to_string(no);
    if (no == 1) {
      if (l != windowsCsvHeader() && l != windowsCsvHeaderV5() && l != windowsCsvHeaderV4() && l != windowsCsvHeaderV3() &&
          l != windowsCsvHeaderV2() && l != windowsCsvHeaderV1())
        throw std::runtime_error(where + ": not a celc windows.csv header");
      continue;
    }
    if (l.empty()) continue;
    const bool last = i + 1 == lines.size();
    const auto f = splitList(l, ',');
    try {
      if (f.size() != 16 && f.size() != 23 && f.size() != 24 && f.size() != 31 && f.size() != 34 &&
          f.size() != 38)
        throw std::runtime_error(where + ": expected 16, 23, 24, 31, 34 or 38 columns, got " + std::to_string(f.size()));
      WindowsCsvRow r;
      r.window = static_cast<std::int64_t>(toDouble(f[0], where, "window"));
      r.t_start = toDouble(f[1], where, "t_start");
      r.t_end = toDouble(f[2], where, "t_end");
      r.n_events = static_cast<std::int64_t>(toDouble(f[3], where, "n_events"));
      r.n_clusters = static_cast<int>(toDouble(f[4], where, "n_clusters"));
      r.method = f[5];
      r.status = f[6];
      if (r.method.empty() || r.status.empty()) throw std::runtime_error(where + ": empty method or status");
      r.has_v = !f[7].empty();
      if (r.has_v) r.v = Vec3(toDouble(f[7], where, "vx"), toDouble(f[8], where, "vy"), toDouble(f[9], where, "vz"));
      r.has_gt = !f[10].empty();
      if (r.has_gt)
        r.gt = Vec3(toDouble(f[10], where, "gt_vx"), toDouble(f[11], where, "gt_vy"), toDouble(f[12], where, "gt_vz"));
      r.has_metrics = !f[13].empty();
      if (r.has_metrics) {
        r.eps = toDouble(f[13], where, "eps");
        r.phi = toDouble(f[14], where, "phi");
      }
      if (!f[15].empty()) r.runtime_ms = toDouble(f[15], where, "runtime_ms");
      if (f.size() >= 23) {
        r.reason = f[16];
        if (!f[17].empty()) r.sigma_deg = toDouble(f[17], where, "sigma_deg");
        if (!f[18].empty()) r.parallax = toDouble(f[18], where, "parallax");
        if (!f[19].empty()) r.n_lines = static_cast<int>(toDouble(f[19], where, "n_lines"));
        r.has_omega = !f[20].empty();
        if (r.has_omega)
          r.omega = Vec3(toDouble(f[20], where, "wx"), toDouble(f[21], where, "wy"), toDouble(f[22], where, "wz"));
      }
      if (f.size() >= 24 && !f[23].empty()) r.translation_px = toDouble(f[23], where, "translation_px");
      if (f.size() >= 31 && !f[26].empty()) {
        r.has_truth = true;
        if (!f[24].empty()) r.purity = toDouble(f[24], where, "purity");
        r.impure_clusters = static_cast<int>(toDouble(f[25], where, "impure_clusters"));
        r.edges = static_cast<int>(toDouble(f[26], where, "edges"));
        r.edges_complete = static_cast<int>(toDouble(f[27], where, "edges_complete"));
        if (!f[28].empty()) r.coverage = toDouble(f[28], where, "coverage");
        if (!f[29].empty()) r.noise_admitted = toDouble(f[29], where, "noise_admitted");
        if (!f[30].empty()) r.oracle_phi = toDouble(f[30], where, "oracle_phi");
      }
      if (f.size() >= 34) {
        if (!f[31].empty()) r.sigma_fisher_deg = toDouble(f[31], where, "sigma_fisher_deg");
        if (!f[32].empty()) r.sigma_budget_deg = toDouble(f[32], where, "sigma_budget_deg");
        r.sigma_rule = f[33];
      }
      if (f.size() == 38) {
        r.model = f[34];
        r.has_acceleration = !f[35].empty();
        if (r.has_acceleration)
          r.acceleration = Vec3(toDouble(f[35], where, "ax"), toDouble(f[36], where, "ay"), toDouble(f[37], where, "az"));
      }
      rows.push_back(r);
    } catch (const std::runtime_error&) {
      if (last && !complete_last && tolerate_truncated_tail) break;  // interrupted write
      throw;
    }
  }
  if (lines.empty()) throw std::runtime_error(path + ": empty file");
  return rows;
}

std::string truthSummaryMarkdown(const std::vector<WindowsCsvRow>& rows) {
  std::vector<double> purity, coverage, ml_phi, oracle_phi;
  int windows = 0, few_impure = 0, edges = 0, complete = 0, within = 0, compared = 0;
  for (const WindowsCsvRow& r : rows) {
    if (r.method != "celc_ml" || !r.has_truth) continue;
    ++windows;
    if (std::isfinite(r.purity)) purity.push_back(r.purity);
    if (std::isfinite(r.coverage)) coverage.push_back(r.coverage);
    if (r.impure_clusters <= 1) ++few_impure;
    edges += r.edges;
    complete += r.edges_complete;
    if (std::isfinite(r.oracle_phi)) {
      ++compared;
      oracle_phi.push_back(r.oracle_phi);
      const double phi = r.has_metrics ? r.phi : M_PI;  // no answer: as far off as can be
      ml_phi.push_back(phi);
      if (phi <= std::max(1.5 * r.oracle_phi, r.oracle_phi + M_PI / 180.0)) ++within;
    }
  }
  if (windows == 0) return "";
  std::ostringstream o;
  o << "Clusters against the truth labels (" << windows << " windows; docs/clustering.md):\n\n"
    << "- event-weighted purity, median window: " << fmt(median(purity), 3) << "\n"
    << "- windows with at most one cluster below 95% purity: " << few_impure << " of " << windows << "\n"
    << "- edges with 80% of their events in one cluster: " << complete << " of " << edges << "\n"
    << "- coverage of the edges' events, median window: " << fmt(median(coverage), 3) << "\n";
  if (compared > 0)
    o << "- celc_ml within max(1.5x, +1 deg) of celc_ml on the true clusters (the oracle): " << within << " of "
      << compared << " windows; median phi " << fmt(median(ml_phi), 4) << " rad against the oracle's "
      << fmt(median(oracle_phi), 4) << " rad\n";
  return o.str();
}

std::vector<MethodSummary> summarize(const std::vector<WindowsCsvRow>& rows, double max_sigma_deg) {
  std::vector<std::string> order;
  std::map<std::string, std::vector<const WindowsCsvRow*>> by;
  for (const auto& r : rows) {
    if (!by.count(r.method)) order.push_back(r.method);
    by[r.method].push_back(&r);
  }
  std::vector<MethodSummary> out;
  for (const auto& name : order) {
    MethodSummary s;
    s.method = name;
    std::vector<double> eps, phi, rt;
    Vec3 sum = Vec3::Zero();
    std::vector<Vec3> dirs;
    std::vector<double> kept_phi;
    Vec3 kept_sum = Vec3::Zero();
    s.max_sigma_deg = max_sigma_deg;
    for (const WindowsCsvRow* r : by[name]) {
      ++s.windows;
      if (r->status != "ok") continue;
      ++s.ok;
      if (r->sigma_deg <= max_sigma_deg) {  // NaN (no sigma) is never kept
        ++s.kept;
        s.kept_windows.push_back(r->window);
        if (r->has_v && r->v.norm() > 0) kept_sum += r->v.normalized();
        if (r->has_metrics) {
          ++s.kept_with_metrics;
          kept_phi.push_back(r->phi);
        }
      }
      rt.push_back(r->runtime_ms);
      if (r->has_v && r->v.norm() > 0) {
        dirs.push_back(r->v.normalized());
        sum += dirs.back();
      }
      if (!r->has_metrics) continue;
      ++s.with_metrics;
      eps.push_back(r->eps);
      phi.push_back(r->phi);
    }
    s.eps_mean = mean(eps);
    s.eps_median = median(eps);
    s.phi_mean = mean(phi);
    s.phi_median = median(phi);
    s.runtime_ms_median = median(rt);
    s.kept_phi_mean = mean(kept_phi);
    s.kept_phi_median = median(kept_phi);
    if (s.kept > 0) s.kept_resultant_length = kept_sum.norm() / static_cast<double>(s.kept);
    std::sort(s.kept_windows.begin(), s.kept_windows.end());
    if (!dirs.empty()) {
      s.resultant_length = sum.norm() / static_cast<double>(dirs.size());
      const Vec3 m = sum.norm() > 0 ? Vec3(sum.normalized()) : dirs.front();
      std::vector<double> ang;
      for (const auto& d : dirs) ang.push_back(directionAngle(d, m));
      s.spread_median = median(ang);
    }
    out.push_back(s);
  }
  return out;
}

std::string windowRanges(const std::vector<std::int64_t>& windows, std::size_t max_ranges) {
  std::string out;
  std::size_t ranges = 0;
  for (std::size_t i = 0; i < windows.size();) {
    std::size_t j = i;
    while (j + 1 < windows.size() && windows[j + 1] <= windows[j] + 1) ++j;
    if (ranges == max_ranges) {
      out += ", ... (" + std::to_string(windows.size()) + " windows)";
      break;
    }
    out += (out.empty() ? "" : ", ") + std::to_string(windows[i]);
    if (windows[j] != windows[i]) out += "-" + std::to_string(windows[j]);
    ++ranges;
    i = j + 1;
  }
  return out;
}

std::string summaryMarkdown(const std::string& title, const std::vector<MethodSummary>& methods,
                            const std::vector<std::string>& notes) {
  std::ostringstream o;
  o << "# " << title << "\n\n";
  for (const auto& n : notes) o << "- " << n << "\n";
  if (!notes.empty()) o << "\n";
  o << "| method | windows | ok | with ground truth | mean eps (unit-vector distance) | median eps (unit-vector distance) | mean phi [rad] | median phi [rad] | direction consistency R | median spread [rad] | median runtime [ms] |\n"
    << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& m : methods)
    o << "| " << m.method << " | " << m.windows << " | " << m.ok << " | " << m.with_metrics << " | "
      << fmt(m.eps_mean) << " | " << fmt(m.eps_median) << " | " << fmt(m.phi_mean) << " | "
      << fmt(m.phi_median) << " | " << fmt(m.resultant_length, 3) << " | " << fmt(m.spread_median, 3)
      << " | " << fmt(m.runtime_ms_median, 2) << " |\n";
  o << "\neps = |v_gt - v|, phi = acos(v_gt . v) on unit vectors, over the windows with status ok "
       "and ground truth. R = |mean of the unit estimates| over the ok windows (1: every window "
       "gives the same direction); spread = angle of each estimate to their mean direction.\n";
  // The windows a user would keep: ok and a small enough uncertainty.
  const double thr = methods.empty() ? kDefaultKeepSigmaDeg : methods.front().max_sigma_deg;
  o << "\nThe windows a user would keep: status ok and sigma_deg <= " << fmt(thr, 1)
    << " deg (rows without sigma_deg are not kept); kept windows: their indices (windows.csv column "
       "window), the rows the kept columns describe.\n\n"
    << "| method | ok | kept | kept with ground truth | mean phi kept [rad] | median phi kept [rad] | R kept | kept windows |\n"
    << "|---|---|---|---|---|---|---|---|\n";
  for (const auto& m : methods)
    o << "| " << m.method << " | " << m.ok << " | " << m.kept << " | " << m.kept_with_metrics << " | "
      << fmt(m.kept_phi_mean) << " | " << fmt(m.kept_phi_median) << " | " << fmt(m.kept_resultant_length, 3)
      << " | " << (m.kept_windows.empty() ? std::string("-") : windowRanges(m.kept_windows)) << " |\n";
  return o.str();
}

std::string methodDisplayName(const std::string& m) {
  if (m == "celc") return "CELC";
  if (m == "celc_opt") return "CELC+opt";
  if (m == "celc_ml") return "CELC+ML";
  if (m == "ce3lc") return "CE3LC";
  if (m == "npt") return "N-point";
  return m;
}

namespace {
// Columns: every method of any sequence, in order of first appearance.
std::vector<std::string> columns(const std::vector<SequenceSummary>& seqs) {
  std::vector<std::string> cols;
  for (const auto& s : seqs)
    for (const auto& m : s.methods)
      if (std::find(cols.begin(), cols.end(), m.method) == cols.end()) cols.push_back(m.method);
  return cols;
}
double valueOf(const SequenceSummary& s, const std::string& method, bool eps) {
  for (const auto& m : s.methods)
    if (m.method == method) return eps ? m.eps_mean : m.phi_mean;
  return NAN;
}
// The method with the smallest finite value of a row.
int best(const SequenceSummary& s, const std::vector<std::string>& cols, bool eps) {
  int b = -1;
  for (size_t i = 0; i < cols.size(); ++i) {
    const double v = valueOf(s, cols[i], eps);
    if (std::isfinite(v) && (b < 0 || v < valueOf(s, cols[static_cast<size_t>(b)], eps))) b = static_cast<int>(i);
  }
  return b;
}
std::string latexEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '_' || c == '&' || c == '%' || c == '#') o += '\\';
    o += c;
  }
  return o;
}
}  // namespace

std::string tableMarkdown(const std::vector<SequenceSummary>& seqs) {
  const auto cols = columns(seqs);
  std::ostringstream o;
  o << "| sequence | error |";
  for (const auto& c : cols) o << " " << methodDisplayName(c) << " |";
  o << "\n|---|---|";
  for (size_t i = 0; i < cols.size(); ++i) o << "---|";
  o << "\n";
  for (const auto& s : seqs)
    for (bool eps : {true, false}) {
      const int b = best(s, cols, eps);
      o << "| " << s.label << " | " << (eps ? "eps (unit-vector distance)" : "phi [rad]") << " |";
      for (size_t i = 0; i < cols.size(); ++i) {
        const std::string v = fmt(valueOf(s, cols[i], eps));
        o << " " << (static_cast<int>(i) == b ? "**" + v + "**" : v) << " |";
      }
      o << "\n";
    }
  o << "\neps = |v_gt - v|: the distance between the unit ground-truth and unit estimated directions "
       "(0 to 2, no unit); phi = acos(v_gt . v) [rad]; means over the windows with status ok and ground truth.\n";
  return o.str();
}

std::string tableLatex(const std::vector<SequenceSummary>& seqs) {
  const auto cols = columns(seqs);
  std::ostringstream o;
  o << "% celc table: mean errors over the windows with ground truth; best per row in bold\n"
    << "% epsilon = |v_gt - v| between unit vectors (0 to 2, no unit), phi = acos(v_gt . v) [rad]\n"
    << "\\begin{tabular}{ll" << std::string(cols.size(), 'c') << "}\n\\toprule\nSequence & Error";
  for (const auto& c : cols) o << " & " << latexEscape(methodDisplayName(c));
  o << " \\\\\n\\midrule\n";
  for (size_t k = 0; k < seqs.size(); ++k) {
    const auto& s = seqs[k];
    for (bool eps : {true, false}) {
      const int b = best(s, cols, eps);
      o << (eps ? "\\multirow{2}{*}{" + latexEscape(s.label) + "}" : std::string()) << " & "
        << (eps ? "$\\epsilon$ (unit-vector dist.)" : "$\\phi$ [rad]");
      for (size_t i = 0; i < cols.size(); ++i) {
        const std::string v = fmt(valueOf(s, cols[i], eps));
        o << " & " << (static_cast<int>(i) == b ? "\\textbf{" + v + "}" : v);
      }
      o << " \\\\\n";
    }
    if (k + 1 < seqs.size()) o << "\\midrule\n";
  }
  o << "\\bottomrule\n\\end{tabular}\n";
  return o.str();
}

std::string tableCsv(const std::vector<SequenceSummary>& seqs) {
  std::ostringstream o;
  o << "sequence,method,windows,ok,with_metrics,eps_mean,eps_median,phi_mean,phi_median\n";
  for (const auto& s : seqs)
    for (const auto& m : s.methods) {
      auto num = [&](double x) { return std::isfinite(x) ? fmt(x, 6) : std::string(); };
      o << s.label << "," << m.method << "," << m.windows << "," << m.ok << "," << m.with_metrics
        << "," << num(m.eps_mean) << "," << num(m.eps_median) << "," << num(m.phi_mean) << ","
        << num(m.phi_median) << "\n";
    }
  return o.str();
}

}  // namespace celc
