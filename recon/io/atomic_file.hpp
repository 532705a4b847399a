// Writing a file so that a reader, or a crash, never sees half of it.
#pragma once

#include <string>
#include <string_view>

#include "recon/core/status.hpp"

namespace bodyscan {

// Writes beside the target, fsyncs, renames over the target, then syncs the folder
// (best effort). On any failure the target is untouched and the message says what
// the system refused.
Status write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace bodyscan
