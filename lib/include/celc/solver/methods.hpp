#pragma once
/// \file methods.hpp
/// The solver methods and their names, as used in every CSV, table and option.
#include <string>
#include <vector>

namespace celc {

/// celc: CELC linear; celc_opt: CELC refined (v alone); celc_ml: v refined
/// jointly with every cluster's lines; ce3lc: the paper's baseline; npt: Gao
/// et al.'s N-point linear solver; celc_acc: CELC with a constant
/// acceleration (linear in v and a; solver/celc_acc.hpp).
enum class Method { Celc, CelcOpt, CelcMl, Ce3lc, Npt, CelcAcc };
std::string toString(Method method);
/// Parses "celc", "celc_opt", "celc_ml", "ce3lc", "npt", "celc_acc"; throws std::invalid_argument otherwise.
Method parseMethod(const std::string& name);
/// Parses a comma-separated list of method names ("all": every method); duplicates dropped.
std::vector<Method> parseMethodList(const std::string& list);
/// Every method, in the order of the enum ("all" in a method list).
const std::vector<Method>& allMethods();
/// The paper's and the peers' methods, every method but celc_acc: what the
/// studies (`celc simulate`, the peers' study) run unless told otherwise.
const std::vector<Method>& paperMethods();
/// What `celc run`, `batch`, `solve` and the Python module's run() solve
/// unless told otherwise: paperMethods() and celc_acc, whose row holds the
/// window's choice between the constant-velocity and the acceleration model.
const std::vector<Method>& runMethods();

}  // namespace celc
