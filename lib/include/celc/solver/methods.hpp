#pragma once
/// \file methods.hpp
/// The solver methods and their names, as used in every CSV, table and option.
#include <string>
#include <vector>

namespace celc {

/// celc: CELC linear; celc_opt: CELC refined (v alone); celc_ml: v refined
/// jointly with every cluster's lines; ce3lc: the paper's baseline; npt: Gao
/// et al.'s N-point linear solver.
enum class Method { Celc, CelcOpt, CelcMl, Ce3lc, Npt };
std::string toString(Method method);
/// Parses "celc", "celc_opt", "celc_ml", "ce3lc", "npt"; throws std::invalid_argument otherwise.
Method parseMethod(const std::string& name);
/// Parses a comma-separated list of method names ("all": every method); duplicates dropped.
std::vector<Method> parseMethodList(const std::string& list);
/// Every method, in the order of the enum.
const std::vector<Method>& allMethods();

}  // namespace celc
