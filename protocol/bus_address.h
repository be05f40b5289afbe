// The address of a CAN link between processes (DESIGN.md "The CAN transport between processes"): the
// one parser of `--bus ADDR` / `--can IFACE` for `exotwin serve` and `exotwin-controller`.
//   unix:PATH          a Unix datagram socket at PATH (the twin's end; the controller's end is
//                      PATH.ctl), each created mode 0600;
//   udp:HOST:PORT      UDP, the twin on HOST:PORT, the controller on HOST:PORT+1; HOST an IPv4
//                      address or "localhost" (127.0.0.1);
//   can:IFACE          SocketCAN interface IFACE (protocol/socketcan_bus.h);
//   shm:NAME           the shared-memory segment /dev/shm/NAME, two processes on one host
//                      (protocol/shm_link.h); NAME 1..200 of [A-Za-z0-9._-], not starting with '.'.
#pragma once
#include <cstdint>
#include <string>

namespace exotwin {

enum class BusKind { kUnix, kUdp, kSocketCan, kShm };

// Which end of the link a process is: the twin (`exotwin serve`) or the controller.
enum class LinkEnd { kTwin, kController };

struct BusAddress {
  BusKind kind = BusKind::kUnix;
  std::string text;       // as given, for messages
  std::string path;       // kUnix: the twin's socket path; kShm: NAME
  std::string host;       // kUdp: dotted IPv4 address
  uint16_t port = 0;      // kUdp: the twin's port (the controller's is port + 1)
  std::string interface;  // kSocketCan
  // kUdp: true when host is in 127.0.0.0/8.
  bool loopback() const;
  // The local and peer socket of `end`: unix paths or "HOST:PORT" (kShm: the segment and the end).
  std::string LocalName(LinkEnd end) const;
  std::string PeerName(LinkEnd end) const;
};

// Parses ADDR; throws InputError "<what>: '<ADDR>': <reason>, expected unix:PATH, udp:HOST:PORT,
// can:IFACE or shm:NAME" (`what` names the option, e.g. "--bus").
BusAddress ParseBusAddress(const std::string& text, const std::string& what = "--bus");

}  // namespace exotwin
