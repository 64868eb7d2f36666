#include "celc/pipeline/peer_study.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <sstream>

#include "celc/eval/crlb.hpp"
#include "celc/eval/statistics.hpp"
#include "celc/pipeline/study_engine.hpp"

namespace celc {

double PeerCell::parallaxRatio(const PeerSceneOptions& base) const {
  return speed * base.duration / (0.5 * (base.depth_range[0] + base.depth_range[1]));
}

void PeerCell::apply(PeerSceneOptions& s) const {
  s.speed = speed;
  s.event_noise_px = sigma_px;
  s.omega_error_deg_s = omega_error_deg_s;
  s.n_lines = lines;
  s.events_per_line = events_per_line;
  s.outlier_fraction = outliers;
}

std::vector<PeerCell> peerStudyCells() {
  std::vector<PeerCell> cells;
  auto key = [](const PeerCell& c) {
    std::ostringstream k;
    k << c.speed << "|" << c.sigma_px << "|" << c.omega_error_deg_s << "|" << c.lines << "|"
      << c.events_per_line << "|" << c.outliers;
    return k.str();
  };
  std::map<std::string, size_t> index;
  auto add = [&](PeerCell c, const std::string& group) {
    const std::string k = key(c);
    if (auto it = index.find(k); it != index.end()) {
      cells[it->second].groups += ";" + group;
      return;
    }
    c.groups = group;
    index[k] = cells.size();
    cells.push_back(c);
  };
  const PeerCell base;
  add(base, "base");
  for (double V : {1.0, 2.0, 5.0, 16.0})
    for (double s : {0.0, 0.5, 1.0, 2.0}) {
      PeerCell c = base;
      c.speed = V;
      c.sigma_px = s;
      add(c, "grid");
    }
  for (double w : {0.0, 2.0, 5.0, 10.0}) {
    PeerCell c = base;
    c.omega_error_deg_s = w;
    add(c, "omega");
  }
  for (int l : {2, 5, 10}) {
    PeerCell c = base;
    c.lines = l;
    add(c, "lines");
  }
  for (int e : {20, 100, 200, 500}) {
    PeerCell c = base;
    c.events_per_line = e;
    add(c, "events");
  }
  for (double o : {0.0, 0.1}) {
    PeerCell c = base;
    c.outliers = o;
    add(c, "outliers");
  }
  return cells;
}

void describe(FieldVisitor& v, PeerStudyConfig& c) {
  v.field({"trials", "", "trials per cell", atLeast(1)}, c.trials);
  v.field({"seed", "", "the trials' seed"}, c.seed);
}

std::string PeerStudyConfig::validate() const {
  std::string e = scene.validate() + inSection("solver", solver.validate()) + rangeProblemsOf(*this);
  if (methods.empty()) e += "no methods; ";
  return e;
}

std::uint32_t peerCellKey(const PeerCell& c) {
  std::ostringstream k;
  k << c.speed << "|" << c.sigma_px << "|" << c.omega_error_deg_s << "|" << c.lines << "|"
    << c.events_per_line << "|" << c.outliers;
  std::uint32_t h = 2166136261u;  // FNV-1a
  for (char ch : k.str()) h = (h ^ static_cast<unsigned char>(ch)) * 16777619u;
  return h;
}

std::vector<PeerCellResult> runPeerStudy(const std::vector<PeerCell>& cells,
                                         const PeerStudyConfig& config, int threads,
                                         const std::function<void(int, int)>& progress) {
  const int n_cells = static_cast<int>(cells.size());
  const int n_trials = config.trials;
  const int n_methods = static_cast<int>(config.methods.size());
  constexpr double kDeg = 180.0 / M_PI;

  StudyPlan plan;
  for (const PeerCell& cell : cells) plan.cells.push_back({peerCellKey(cell)});
  plan.trials = n_trials;
  plan.methods = n_methods;
  plan.seed = config.seed;
  plan.threads = threads;
  // Per trial: every method's outcome, and the bound as the reference [rad]
  // (NaN when the trial has none).
  const StudyOutcomes outcomes = runStudy(
      plan,
      [&](std::size_t ci, int, std::mt19937_64& rng) {
        PeerSceneOptions scene = config.scene;
        cells[ci].apply(scene);
        const PeerSceneTrial tr = generatePeerScene(scene, rng);
        TrialOutcome out;
        if (!tr.ok) return out;
        const CrlbResult b = velocityDirectionCrlb(tr.truth, tr.true_motion, tr.true_direction,
                                                   scene.event_noise_px);
        if (b.ok) out.reference = b.rms_rad;
        const SampleSeeds seeds{rng(), config.solver.refine.seed};
        const auto res = solveMethods(tr.observations, tr.given_motion, config.methods, config.solver, seeds);
        out.methods = scoreResults(res, tr.true_direction);
        return out;
      },
      progress);

  std::vector<PeerCellResult> rows;
  for (int ci = 0; ci < n_cells; ++ci) {
    for (int m = 0; m < n_methods; ++m) {
      PeerCellResult r;
      r.cell = cells[static_cast<size_t>(ci)];
      r.method = config.methods[static_cast<size_t>(m)];
      r.trials = n_trials;
      std::vector<double> phi, agn, time, bound;
      double sq = 0.0, bound_sq = 0.0;
      int above = 0, n_bound = 0;
      for (int t = 0; t < n_trials; ++t) {
        const TrialOutcome& trial = outcomes.trial(static_cast<size_t>(ci), t);
        const MethodOutcome& o = trial.methods[static_cast<size_t>(m)];
        if (!o.ok) continue;
        phi.push_back(o.phi * kDeg);
        agn.push_back(o.phi_sign_agnostic * kDeg);
        time.push_back(o.time_us);
        sq += o.phi_sign_agnostic * o.phi_sign_agnostic;
        if (o.phi_sign_agnostic * kDeg > 5.0) ++above;
        // NaN: no bound for this trial; +inf: direction unobservable (kept).
        const double bound_rad = trial.reference;
        if (!std::isnan(bound_rad)) {
          bound.push_back(bound_rad * kDeg);
          bound_sq += bound_rad * bound_rad;
          ++n_bound;
        }
      }
      r.n_ok = static_cast<int>(phi.size());
      r.phi_median_deg = median(phi);
      r.phi_mean_deg = mean(phi);
      r.phi_median_agn_deg = median(agn);
      r.phi_mean_agn_deg = mean(agn);
      r.share_above_5deg = r.n_ok > 0 ? static_cast<double>(above) / r.n_ok : NAN;
      r.rms_agn_deg = r.n_ok > 0 ? std::sqrt(sq / r.n_ok) * kDeg : NAN;
      r.crlb_rms_deg = n_bound > 0 ? std::sqrt(bound_sq / n_bound) * kDeg : NAN;
      r.crlb_median_deg = bound.empty() ? NAN : median(bound);
      r.ratio = r.crlb_rms_deg > 0.0 && std::isfinite(r.crlb_rms_deg) ? r.rms_agn_deg / r.crlb_rms_deg
                                                                      : NAN;
      r.time_median_us = median(time);
      rows.push_back(r);
    }
  }
  return rows;
}

std::string peerCsvHeader() {
  return "groups,speed_m_s,parallax_ratio,sigma_px,omega_error_deg_s,lines,events_per_line,"
         "outliers,method,trials,n_ok,phi_median_deg,phi_mean_deg,phi_median_agn_deg,"
         "phi_mean_agn_deg,share_above_5deg,rms_agn_deg,crlb_rms_deg,crlb_median_deg,rms_over_crlb,"
         "time_median_us";
}

std::string peerCsvRow(const PeerCellResult& r, const PeerSceneOptions& base) {
  std::ostringstream os;
  os.precision(7);
  auto num = [&](double x) {
    os << ",";
    if (std::isfinite(x)) os << x;
  };
  os << r.cell.groups << "," << r.cell.speed;
  num(r.cell.parallaxRatio(base));
  num(r.cell.sigma_px);
  num(r.cell.omega_error_deg_s);
  os << "," << r.cell.lines << "," << r.cell.events_per_line;
  num(r.cell.outliers);
  os << "," << toString(r.method) << "," << r.trials << "," << r.n_ok;
  for (double x : {r.phi_median_deg, r.phi_mean_deg, r.phi_median_agn_deg, r.phi_mean_agn_deg,
                   r.share_above_5deg, r.rms_agn_deg, r.crlb_rms_deg, r.crlb_median_deg, r.ratio,
                   r.time_median_us})
    num(x);
  return os.str();
}

}  // namespace celc
