// The options that choose, pose and place the simulated rig's subject, shared by
// `bodyscan scan`, `bodyscan sim render` and `bodyscan serve`.
#pragma once

#include <string>

#include "core/status.hpp"
#include "pipeline/rig_backend.hpp"

namespace bodyscan::cli {

// The options' lines for a command's --help.
extern const char* const kSubjectOptionsHelp;

// True for the flags below; each takes one value.
bool is_subject_option(const std::string& flag);

// Sets what `flag` (one of is_subject_option's) with `value` asks; an error says
// what the value should have been.
Status set_subject_option(const std::string& flag, const std::string& value, pipeline::SimulatedSubject* subject);

}  // namespace bodyscan::cli
