#pragma once
// Where a MAVLink peer is, written the way MAVSDK and mavproxy write it:
//   udp://[HOST]:PORT        listen on PORT (HOST: the local address, default every one) and
//                            reply to whoever sent last — how PX4 SITL reaches an offboard
//                            program on 14540 + instance
//   udpout://HOST:PORT       send to HOST:PORT from an ephemeral port, read the replies there
//   tcp://HOST:PORT          connect to a TCP server (ArduPilot SITL serves 5760 + 10·instance)
//   serial:///dev/TTY:BAUD   a serial port (an autopilot's TELEM port wired to the companion
//                            computer's UART, or its USB port) at BAUD bits per second
// Parsing is separate from opening, and lives with the fleet file, so that `eamos check` (and
// an editor) reports a wrong URL at its line, long before the mavlink adapter opens a socket.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace eamos::fleet {

enum class LinkKind { udp_listen, udp_out, tcp_client, serial };

struct Endpoint {
  LinkKind kind = LinkKind::udp_listen;
  std::string host;    ///< numeric IPv4 address or host name; "" = every local address (listen)
  uint16_t port = 0;   ///< 1…65535
  std::string device;  ///< serial: the device's absolute path
  unsigned baud = 0;   ///< serial: bits per second, one of the standard rates (kSerialBauds)
  std::string url;     ///< as written, for messages
};

/// The rates a serial:// URL may give: those Linux's termios names.
inline constexpr unsigned kSerialBauds[] = {9600,   19200,  38400,   57600,   115200,  230400,  460800,
                                            500000, 576000, 921600, 1000000, 1500000, 2000000, 3000000};

struct EndpointResult {
  std::optional<Endpoint> endpoint;  ///< set when the URL is valid
  /// What is wrong and what a valid URL looks like, without the URL itself: the caller says
  /// where it came from ("connection of drone 'A': …", "connection 'udp:14540': …").
  std::string error;
};

EndpointResult parse_link_url(std::string_view url);

}  // namespace eamos::fleet
