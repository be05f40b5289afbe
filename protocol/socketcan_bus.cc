#include "protocol/socketcan_bus.h"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/sockios.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "core/error.h"

namespace exotwin {

std::unique_ptr<SocketCanBus> SocketCanBus::Open(const std::string& interface, std::vector<uint16_t> accept_ids) {
  auto fail = [&](const std::string& what) {
    throw InputError("CAN interface '" + interface + "': " + what + ": " + std::strerror(errno));
  };
  if (interface.empty() || interface.size() >= IFNAMSIZ) {
    errno = EINVAL;
    fail("expected an interface name of 1.." + std::to_string(IFNAMSIZ - 1) + " characters");
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) fail("cannot open a CAN_RAW socket (kernel without SocketCAN?)");
  std::unique_ptr<SocketCanBus> bus(new SocketCanBus(fd, interface));  // closes fd on throw
  const unsigned index = ::if_nametoindex(interface.c_str());
  if (index == 0) fail("no such network interface");
  if (!accept_ids.empty()) {
    std::vector<can_filter> filters;
    for (uint16_t id : accept_ids) filters.push_back({id, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG});
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0)
      fail("cannot set the receive filter");
  }
  const can_err_mask_t err_mask = CAN_ERR_MASK;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) != 0)
    fail("cannot enable error frames");
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) fail("cannot bind");
  return bus;
}

SocketCanBus::~SocketCanBus() {
  if (fd_ >= 0) ::close(fd_);
}

CanStatus SocketCanBus::Send(const CanFrame& frame) {
  if (!IsValidDataFrame(frame)) return CanStatus::kError;
  if (bus_off_) return CanStatus::kBusOff;
  can_frame cf{};
  cf.can_id = frame.id;
  cf.can_dlc = frame.dlc;
  std::memcpy(cf.data, frame.data.data(), frame.dlc);
  const ssize_t n = ::write(fd_, &cf, sizeof cf);
  if (n == static_cast<ssize_t>(sizeof cf)) return CanStatus::kOk;
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) return CanStatus::kQueueFull;
  if (n < 0 && (errno == ENETDOWN || errno == ENETUNREACH)) return CanStatus::kBusOff;
  return CanStatus::kError;
}

CanStatus SocketCanBus::Receive(CanFrame* out) {
  can_frame cf{};
  const ssize_t n = ::read(fd_, &cf, sizeof cf);
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return CanStatus::kNoFrame;
  if (n != static_cast<ssize_t>(sizeof cf)) return CanStatus::kError;
  timeval tv{};
  if (::ioctl(fd_, SIOCGSTAMP, &tv) != 0) {
    timespec ts{};
    ::clock_gettime(CLOCK_REALTIME, &ts);
    tv.tv_sec = ts.tv_sec;
    tv.tv_usec = ts.tv_nsec / 1000;
  }
  *out = CanFrame{};
  out->t = static_cast<double>(tv.tv_sec) + 1e-6 * static_cast<double>(tv.tv_usec);
  if (cf.can_id & CAN_ERR_FLAG) {
    if (cf.can_id & CAN_ERR_BUSOFF) bus_off_ = true;
    if (cf.can_id & CAN_ERR_RESTARTED) bus_off_ = false;
    out->error = true;
    return CanStatus::kError;
  }
  if (cf.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) return CanStatus::kNoFrame;  // not classic 11-bit data
  out->id = static_cast<uint16_t>(cf.can_id & CAN_SFF_MASK);
  out->dlc = cf.can_dlc > 8 ? 8 : cf.can_dlc;
  std::memcpy(out->data.data(), cf.data, out->dlc);
  return CanStatus::kOk;
}

}  // namespace exotwin
