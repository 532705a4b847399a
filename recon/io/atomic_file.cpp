#include "recon/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <system_error>

namespace bodyscan {

namespace {
std::string errno_text(int error) { return std::generic_category().message(error); }
}  // namespace

StatusOr<std::string> read_whole_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    const int error = errno;
    return not_found(path + ": cannot open: " + errno_text(error));
  }
  std::string bytes;
  char buffer[1 << 16];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) bytes.append(buffer, n);
  const bool failed = std::ferror(f) != 0;
  const int error = errno;
  std::fclose(f);
  if (failed) return io_error(path + ": cannot read: " + errno_text(error));
  return bytes;
}

Status write_file_atomically(const std::string& path, std::string_view bytes, FileAccess access) {
  // A reader (or a crash) must never see half a file: write beside the target,
  // make it durable, then rename over the target in one step.
  const std::string temp = path + ".tmp-" + std::to_string(::getpid());
  const int fd =
      ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, access == FileAccess::kPrivate ? 0600 : 0666);
  std::FILE* f = fd < 0 ? nullptr : ::fdopen(fd, "wb");
  if (f == nullptr) {
    const int error = errno;
    if (fd >= 0) ::close(fd);
    return io_error(path + ": cannot create " + temp + ": " + errno_text(error));
  }
  // A temporary file left by a crash keeps its old mode; O_CREAT does not reset it.
  if (access == FileAccess::kPrivate && ::fchmod(fd, 0600) != 0) {
    const int error = errno;
    std::fclose(f);
    std::remove(temp.c_str());
    return io_error(path + ": cannot make " + temp + " private: " + errno_text(error));
  }
  auto fail = [&](const std::string& what, int error) {
    if (f != nullptr) std::fclose(f);
    std::remove(temp.c_str());
    return io_error(path + ": " + what + ": " + errno_text(error));
  };
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size()) {
    const int error = errno;
    return fail("cannot write " + temp, error);
  }
  if (std::fflush(f) != 0) {
    const int error = errno;
    return fail("cannot write " + temp, error);
  }
  if (::fsync(::fileno(f)) != 0) {
    const int error = errno;
    return fail("cannot sync " + temp, error);
  }
  const int closed = std::fclose(f);
  const int close_error = errno;
  f = nullptr;
  if (closed != 0) return fail("cannot close " + temp, close_error);
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const int error = errno;
    return fail("cannot rename " + temp + " to " + path, error);
  }
  // Make the rename itself durable. Best effort: the data is already in place, and
  // some file systems refuse fsync on directories.
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  return Status::Ok();
}

}  // namespace bodyscan
