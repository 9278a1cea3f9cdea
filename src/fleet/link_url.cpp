#include "fleet/link_url.h"

#include <charconv>

#include "diag/printable.h"

namespace eamos::fleet {

namespace {

const char* kExamples =
    "udp://:14540, udpout://127.0.0.1:14550, tcp://127.0.0.1:5760 or serial:///dev/ttyAMA0:921600";

EndpointResult bad(const std::string& why) {
  return {std::nullopt, why + " (examples: " + kExamples + ")"};
}

// serial:///dev/ttyAMA0:921600: an absolute device path and a rate termios knows.
EndpointResult parse_serial(std::string_view rest, Endpoint e) {
  size_t colon = rest.rfind(':');
  if (rest.empty() || rest.front() != '/' || colon == std::string_view::npos || colon == 0)
    return bad("write the device's absolute path and its rate, serial:///dev/ttyAMA0:921600");
  e.device = std::string(rest.substr(0, colon));
  std::string_view baud = rest.substr(colon + 1);
  unsigned value = 0;
  auto [end, ec] = std::from_chars(baud.data(), baud.data() + baud.size(), value);
  bool standard = false;
  for (unsigned b : kSerialBauds) standard = standard || b == value;
  if (baud.empty() || ec != std::errc() || end != baud.data() + baud.size() || !standard)
    return bad("rate '" + diag::printable(baud) +
               "' is not a serial rate; give the autopilot port's rate (its SERIALn_BAUD or "
               "SER_TELn_BAUD): 57600, 115200, 921600, …");
  e.baud = value;
  return {e, ""};
}

}  // namespace

EndpointResult parse_link_url(std::string_view url) {
  size_t sep = url.find("://");
  if (sep == std::string_view::npos)
    return bad("no scheme; start with udp://, udpout://, tcp:// or serial://");
  std::string_view scheme = url.substr(0, sep);
  std::string_view rest = url.substr(sep + 3);
  Endpoint e;
  e.url = std::string(url);
  if (scheme == "udp") e.kind = LinkKind::udp_listen;
  else if (scheme == "udpout") e.kind = LinkKind::udp_out;
  else if (scheme == "tcp") e.kind = LinkKind::tcp_client;
  else if (scheme == "serial") e.kind = LinkKind::serial;
  else return bad("unknown scheme '" + diag::printable(scheme) + "'; use udp, udpout, tcp or serial");
  if (e.kind == LinkKind::serial) return parse_serial(rest, e);

  size_t colon = rest.rfind(':');
  if (colon == std::string_view::npos) return bad("no port; write HOST:PORT or :PORT");
  e.host = std::string(rest.substr(0, colon));
  std::string_view port = rest.substr(colon + 1);
  unsigned value = 0;
  auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || ec != std::errc() || end != port.data() + port.size() || value < 1 ||
      value > 65535)
    return bad("port '" + diag::printable(port) + "' is not a number from 1 to 65535");
  e.port = static_cast<uint16_t>(value);
  if (e.host.empty() && e.kind != LinkKind::udp_listen)
    return bad(std::string(scheme) + " needs the peer's host, e.g. 127.0.0.1:" + std::string(port));
  if (e.host.find('/') != std::string::npos || e.host.find('?') != std::string::npos)
    return bad("unexpected path or query after the host");
  return {e, ""};
}

}  // namespace eamos::fleet
