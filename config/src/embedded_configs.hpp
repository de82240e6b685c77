#pragma once

namespace craneassist::config::embedded {

extern const char* const kK70mYaml;
extern const char* const kPlanar2rYaml;

}  // namespace craneassist::config::embedded
