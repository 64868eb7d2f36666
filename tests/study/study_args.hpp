#pragma once
// The command line of the study programs (tests/study/): --trials N and
// --seed S, whole numbers in [1, 1000000]; --help prints the usage.
#include <cstdio>
#include <cstdlib>
#include <string>

namespace celc::study {

/// Reads --trials and --seed into trials and seed (left as they are when not
/// given). Returns -1 to go on, else the exit status: 0 after --help, 1 after
/// a bad argument (a one-line error on stderr naming it).
inline int parseStudyArgs(int argc, char** argv, const char* program, int& trials, int& seed) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "--trials" || a == "--seed") && i + 1 < argc) {
      const char* text = argv[++i];
      char* end = nullptr;
      const long v = std::strtol(text, &end, 10);
      if (end == text || *end != '\0' || v <= 0 || v > 1000000) {
        std::fprintf(stderr, "%s: error: %s '%s': expected a whole number in [1, 1000000]\n", program, a.c_str(),
                     text);
        return 1;
      }
      (a == "--trials" ? trials : seed) = static_cast<int>(v);
    } else {
      std::fprintf(stderr, "usage: %s [--trials N] [--seed S]\n", program);
      return a == "--help" || a == "-h" ? 0 : 1;
    }
  }
  return -1;
}

}  // namespace celc::study
