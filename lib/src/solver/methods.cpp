// Method names.
#include "celc/solver/methods.hpp"

#include <algorithm>
#include <stdexcept>

#include "celc/core/text.hpp"

namespace celc {

std::string toString(Method method) {
  switch (method) {
    case Method::Celc: return "celc";
    case Method::CelcOpt: return "celc_opt";
    case Method::CelcMl: return "celc_ml";
    case Method::Ce3lc: return "ce3lc";
    case Method::Npt: return "npt";
    case Method::CelcAcc: return "celc_acc";
  }
  return "unknown";
}

const std::vector<Method>& paperMethods() {
  static const std::vector<Method> methods{Method::Celc, Method::CelcOpt, Method::CelcMl, Method::Ce3lc, Method::Npt};
  return methods;
}

const std::vector<Method>& runMethods() {
  static const std::vector<Method> methods{Method::Celc,  Method::CelcOpt, Method::CelcMl,
                                           Method::Ce3lc, Method::Npt,     Method::CelcAcc};
  return methods;
}

const std::vector<Method>& allMethods() {
  static const std::vector<Method> all{Method::Celc, Method::CelcOpt, Method::CelcMl,
                                       Method::Ce3lc, Method::Npt, Method::CelcAcc};
  return all;
}

Method parseMethod(const std::string& name) {
  for (Method m : allMethods())
    if (toString(m) == name) return m;
  throw std::invalid_argument("unknown method '" + name +
                              "' (expected celc, celc_opt, celc_ml, ce3lc, npt or celc_acc)");
}

std::vector<Method> parseMethodList(const std::string& list) {
  std::vector<Method> out;
  for (std::string item : splitList(list, ',')) {
    item = trimBlanks(item);
    if (item.empty()) continue;
    if (item == "all") return allMethods();
    const Method m = parseMethod(item);
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  }
  if (out.empty()) throw std::invalid_argument("empty method list");
  return out;
}

}  // namespace celc
