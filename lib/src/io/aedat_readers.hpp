#pragma once
// Private: constructors of the AEDAT readers (the factory in event_reader.cpp uses them).
#include <memory>
#include <string>

#include "celc/io/event_reader.hpp"

namespace celc::detail {
std::unique_ptr<EventReader> openAedat2(const std::string& path, const ReaderOptions& o);
std::unique_ptr<EventReader> openAedat31(const std::string& path, const ReaderOptions& o);
std::unique_ptr<EventReader> openAedat4(const std::string& path, const ReaderOptions& o);
}  // namespace celc::detail
