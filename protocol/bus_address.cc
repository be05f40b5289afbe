#include "protocol/bus_address.h"

#include <arpa/inet.h>
#include <net/if.h>
#include <sys/un.h>

#include <cstdlib>

#include "core/error.h"

namespace exotwin {
namespace {

constexpr const char* kExpected = ", expected unix:PATH, udp:HOST:PORT, can:IFACE or shm:NAME";
constexpr const char* kControllerSuffix = ".ctl";

}  // namespace

bool BusAddress::loopback() const {
  in_addr a{};
  return kind == BusKind::kUdp && ::inet_pton(AF_INET, host.c_str(), &a) == 1 && (ntohl(a.s_addr) >> 24) == 127;
}

std::string BusAddress::LocalName(LinkEnd end) const {
  switch (kind) {
    case BusKind::kUnix: return end == LinkEnd::kTwin ? path : path + kControllerSuffix;
    case BusKind::kUdp: return host + ":" + std::to_string(end == LinkEnd::kTwin ? port : port + 1);
    case BusKind::kSocketCan: return interface;
    case BusKind::kShm: return "/dev/shm/" + path + (end == LinkEnd::kTwin ? " (twin end)" : " (controller end)");
  }
  return "";
}

std::string BusAddress::PeerName(LinkEnd end) const {
  return LocalName(end == LinkEnd::kTwin ? LinkEnd::kController : LinkEnd::kTwin);
}

BusAddress ParseBusAddress(const std::string& text, const std::string& what) {
  auto fail = [&](const std::string& why) -> void { throw InputError(what + ": '" + text + "': " + why + kExpected); };
  BusAddress a;
  a.text = text;
  const size_t colon = text.find(':');
  if (colon == std::string::npos) fail("no scheme");
  const std::string scheme = text.substr(0, colon), rest = text.substr(colon + 1);
  if (scheme == "unix") {
    a.kind = BusKind::kUnix;
    a.path = rest;
    if (rest.empty()) fail("empty socket path");
    if (rest.size() + 4 >= sizeof(sockaddr_un::sun_path))
      fail("socket path longer than " + std::to_string(sizeof(sockaddr_un::sun_path) - 5) + " characters");
  } else if (scheme == "udp") {
    a.kind = BusKind::kUdp;
    const size_t c2 = rest.rfind(':');
    if (c2 == std::string::npos) fail("no port");
    a.host = rest.substr(0, c2);
    if (a.host == "localhost") a.host = "127.0.0.1";
    in_addr ip{};
    if (::inet_pton(AF_INET, a.host.c_str(), &ip) != 1) fail("'" + a.host + "' is not an IPv4 address");
    const std::string port = rest.substr(c2 + 1);
    char* end = nullptr;
    const long p = port.empty() ? -1 : std::strtol(port.c_str(), &end, 10);
    if (p < 1 || p > 65534 || *end != '\0') fail("port '" + port + "' not in 1..65534 (the controller uses port + 1)");
    a.port = static_cast<uint16_t>(p);
  } else if (scheme == "can") {
    a.kind = BusKind::kSocketCan;
    a.interface = rest;
    if (rest.empty() || rest.size() >= IFNAMSIZ)
      fail("expected an interface name of 1.." + std::to_string(IFNAMSIZ - 1) + " characters");
  } else if (scheme == "shm") {
    a.kind = BusKind::kShm;
    a.path = rest;
    if (rest.empty() || rest.size() > 200 || rest[0] == '.' ||
        rest.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-") != std::string::npos)
      fail("expected a segment name of 1..200 characters A-Z a-z 0-9 . _ -, not starting with '.'");
  } else {
    fail("unknown scheme '" + scheme + "'");
  }
  return a;
}

}  // namespace exotwin
