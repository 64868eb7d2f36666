// Validation of the solver options: the ranges of the schema (schema.cpp)
// and the rules that tie fields together.
#include "celc/solver/options.hpp"

namespace celc {

std::string LinearOptions::validate() const { return rangeProblemsOf(*this); }

std::string RefineOptions::validate() const { return rangeProblemsOf(*this); }

std::string NptOptions::validate() const { return rangeProblemsOf(*this); }

std::string MlOptions::validate() const { return rangeProblemsOf(*this); }

std::string AccOptions::validate() const { return rangeProblemsOf(*this); }

std::string UncertaintyOptions::validate() const {
  std::string e = rangeProblemsOf(*this);
  if (witness_rows > 0 && !agreement) e += "witness_rows: > 0 needs agreement: true; ";
  return e;
}

SolverOptions SolverOptions::paper() {
  SolverOptions s;
  s.linear.grid_directions = 0;
  s.linear.grid_starts = 2;
  s.linear.tukey_k = 0.0;
  s.refine.tukey_scale = 0.0;
  s.refine.starts = 1;
  s.ml.grid_starts = 0;
  s.ml.max_events = 5000;
  s.ml.screen_events = 1000;
  s.ml.finalists = 1;
  s.ml.tukey_scale = 0.0;
  s.ml.cheiral_min = 0.0;
  s.uncertainty.cheiral_min = 0.0;
  return s;
}

std::string SolverOptions::validate() const {
  return inSection("linear", linear.validate()) + inSection("refine", refine.validate()) +
         inSection("npt", npt.validate()) + inSection("ml", ml.validate()) + inSection("acc", acc.validate()) +
         inSection("uncertainty", uncertainty.validate());
}

}  // namespace celc
