// Writing a file so that a reader, or a crash, never sees half of it.
#pragma once

#include <string>
#include <string_view>

#include "core/status.hpp"

namespace bodyscan {

enum class FileAccess {
  kUmask,    // 0666 less the process's umask
  kPrivate,  // 0600 from the moment it exists (passwords, keys)
};

// Writes beside the target, fsyncs, renames over the target, then syncs the folder
// (best effort). On any failure the target is untouched and the message says what
// the system refused.
Status write_file_atomically(const std::string& path, std::string_view bytes, FileAccess access = FileAccess::kUmask);

// A whole file's bytes; not found when it cannot be opened, an I/O error when it
// cannot be read to its end.
StatusOr<std::string> read_whole_file(const std::string& path);

}  // namespace bodyscan
