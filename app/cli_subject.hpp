// The options that choose, pose and place the simulated rig's subject, shared by
// `bodyscan scan`, `bodyscan sim render` and `bodyscan serve`.
#pragma once

#include <string>

#include "core/command_line.hpp"
#include "pipeline/rig_backend.hpp"

namespace bodyscan::cli {

// The options' lines for a command's --help.
extern const char* const kSubjectOptionsHelp;

// Declares the options on `cl`; each parsed value is checked and set on `subject`.
void add_subject_options(CommandLine* cl, pipeline::SimulatedSubject* subject);

}  // namespace bodyscan::cli
