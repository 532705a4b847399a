#include "hw/usb/serial_link.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace bodyscan::hw::usb {

namespace {

speed_t baud_constant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: return B115200;
  }
}

int remaining_ms(std::chrono::steady_clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
  return left.count() > 0 ? static_cast<int>(left.count()) : 0;
}

}  // namespace

StatusOr<std::unique_ptr<SerialLink>> SerialLink::open(const std::string& path, int baud) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    std::string hint;
    if (err == EACCES) hint = " (add the user to the 'dialout' group, or install deploy/udev/60-bodyscan.rules)";
    if (err == ENOENT) hint = " (is the board plugged in? `bodyscan devices` lists what is connected)";
    return unavailable("cannot open the controller port " + path + ": " + std::strerror(err) + hint);
  }
  termios tio{};
  if (tcgetattr(fd, &tio) == 0) {
    cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~(CSTOPB | PARENB | CRTSCTS);
    cfsetispeed(&tio, baud_constant(baud));
    cfsetospeed(&tio, baud_constant(baud));
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    if (tcsetattr(fd, TCSANOW, &tio) != 0) {
      const int err = errno;
      ::close(fd);
      return io_error("cannot configure the controller port " + path + ": " + std::strerror(err));
    }
  }
  // A file that is not a terminal (tcgetattr fails) is used as it is: a FIFO or a
  // socket pair in tests.
  tcflush(fd, TCIOFLUSH);
  return std::unique_ptr<SerialLink>(new SerialLink(fd, path));
}

SerialLink::~SerialLink() {
  if (fd_ >= 0) ::close(fd_);
}

Status SerialLink::gone(const char* what, int err) const {
  return unavailable("the controller on " + path_ + " is gone (" + what + ": " + std::strerror(err) +
                     "): is it still plugged in and powered?");
}

Status SerialLink::write(const uint8_t* data, size_t size, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  size_t done = 0;
  while (done < size) {
    ssize_t n = 0;
    int err = 0;
    {
      WireLedger::Send send(ledger_);
      if (!send.open()) return unavailable("the controller on " + path_ + " is taken by the emergency stop");
      n = ::write(fd_, data + done, size - done);
      err = errno;
      if (n > 0) send.sent(data + done, static_cast<size_t>(n));
    }
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && err != EAGAIN && err != EINTR) return gone("write", err);
    pollfd p{fd_, POLLOUT, 0};
    const int r = ::poll(&p, 1, remaining_ms(deadline));
    if (r == 0) return deadline_exceeded("the controller on " + path_ + " does not take commands");
    if (r < 0 && errno != EINTR) return gone("poll", errno);
    if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) return gone("write", EIO);
  }
  return Status::Ok();
}

Status SerialLink::read(uint8_t* data, size_t size, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(fd_, data + done, size - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return gone("read", errno);
    pollfd p{fd_, POLLIN, 0};
    const int left = remaining_ms(deadline);
    const int r = left > 0 ? ::poll(&p, 1, left) : 0;
    if (r == 0) {
      return deadline_exceeded(
          "the controller on " + path_ + " did not answer within " + std::to_string(timeout.count()) + " ms" +
          (done ? " (" + std::to_string(done) + " of " + std::to_string(size) + " bytes came)" : ""));
    }
    if (r < 0 && errno != EINTR) return gone("poll", errno);
    if ((p.revents & (POLLERR | POLLNVAL)) || ((p.revents & POLLHUP) && !(p.revents & POLLIN)))
      return gone("read", EIO);
  }
  return Status::Ok();
}

void SerialLink::discard_input() {
  uint8_t junk[256];
  tcflush(fd_, TCIFLUSH);
  while (::read(fd_, junk, sizeof junk) > 0) {
  }
}

bool SerialLink::emergency_write(const uint8_t* data, size_t size) noexcept {
  size_t done = 0;
  for (int tries = 0; done < size && tries < 50; ++tries) {
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n > 0) {
      ledger_.record(data + done, static_cast<size_t>(n));
      done += static_cast<size_t>(n);
    } else if (n < 0 && errno != EAGAIN && errno != EINTR) {
      return false;
    }
  }
  if (done == size) tcdrain(fd_);
  return done == size;
}

}  // namespace bodyscan::hw::usb
