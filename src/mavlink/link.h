#pragma once
// A MAVLink connection over UDP, TCP or a serial port (fleet/link_url.h) with its own receive
// thread. The thread reads bytes, runs them through the Parser and hands each good frame to
// the FrameHandler — on the link's thread, so the handler must only pass the frame on (the
// adapter posts it to its event loop) and never touch state the loop's thread owns. send() may be called from any thread.
// A TCP connection the peer closes, or a serial port that goes away (USB unplugged), is
// reopened (every second by default) until it is back.
#include <netinet/in.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>

#include "mavlink/frame.h"
#include "fleet/link_url.h"

namespace eamos::mavlink {

using FrameHandler = std::function<void(Frame)>;

struct OpenResult;

class Link {
 public:
  /// Opens the socket (binds, or connects for TCP) or the serial port and starts the receive
  /// thread. `reconnect_s`: TCP and serial, the pause between attempts to reopen.
  /// `verify`: check signed frames against this key from the first datagram on, and drop
  /// unsigned ones when `require_signed` (see verify_with).
  static OpenResult open(const fleet::Endpoint& endpoint, FrameHandler on_frame, double reconnect_s = 1.0,
                         const std::optional<SigningKey>& verify = std::nullopt, bool require_signed = false);
  /// Stops and joins the receive thread, then closes the socket: after it returns the
  /// handler is never called again.
  ~Link();
  Link(const Link&) = delete;
  Link& operator=(const Link&) = delete;

  /// Sends one encoded frame. False when there is nobody to send to yet (udp:// before the
  /// first datagram arrived), or the socket failed (a closed TCP connection).
  bool send(std::span<const uint8_t> bytes);
  /// The local UDP/TCP port (useful when udpout:// picked an ephemeral one).
  uint16_t local_port() const { return local_port_; }
  const fleet::Endpoint& endpoint() const { return endpoint_; }
  /// Parser counters so far (garbage, bad CRCs), copied under the lock.
  ParserStats stats() const;
  /// udp:// only. 0 (the default, before the vehicle is known): replies go to whoever last
  /// sent a valid frame (CRC-checked and parsed) of any system. Else the first valid frame of
  /// system `sysid` fixes the vehicle's address for good: from then on every datagram from
  /// another address is dropped unread and counted (foreign_datagrams), so a forged frame
  /// with the vehicle's system id from another port neither reaches the adapter nor turns
  /// its commands away. A datagram of garbage never redirects the link.
  void follow_only(uint8_t sysid) { follow_sysid_ = sysid; }
  /// udp://: datagrams dropped because they came from another address than the vehicle's.
  uint64_t foreign_datagrams() const { return foreign_datagrams_; }
  /// udp://: the vehicle's address is fixed (see follow_only).
  bool locked() const { return locked_; }
  /// From the next datagram on, signed frames are checked against `key` and dropped when
  /// the signature, its stream's timestamp order or its age is wrong (signing.h); unsigned
  /// frames are dropped too when `required`. Counted in stats().signing_dropped.
  void verify_with(SigningKey key, bool required);
  /// Turns the requirement on or off (after SETUP_SIGNING, say), keeping the key.
  void require_signed(bool required);

 private:
  Link(fleet::Endpoint endpoint, int fd, int wake_read, int wake_write, FrameHandler on_frame);
  void receive_loop();
  /// TCP: reconnects after the peer closed; false when the link is being destroyed.
  bool reconnect();
  /// Parses one read; `from`: its sender (UDP), which the link may follow.
  void handle_bytes(std::span<const uint8_t> bytes, const sockaddr_in* from);
  void follow_sender(const std::vector<Frame>& frames, const sockaddr_in& from);

  fleet::Endpoint endpoint_;
  int fd_ = -1;
  int wake_read_ = -1;   ///< self-pipe: the destructor writes to wake the receive thread
  int wake_write_ = -1;
  int reconnect_ms_ = 1000;
  uint16_t local_port_ = 0;
  FrameHandler on_frame_;
  Parser parser_;               ///< only the receive thread feeds it
  mutable std::mutex mutex_;    ///< guards peer_ and stats_
  sockaddr_in peer_{};          ///< the vehicle's last address (udp://) or the target (udpout://)
  bool has_peer_ = false;
  std::atomic<uint8_t> follow_sysid_{0};  ///< udp://: whose valid frames move peer_
  std::atomic<bool> locked_{false};        ///< udp://: peer_ is the vehicle's, for good
  std::atomic<uint64_t> foreign_datagrams_{0};
  sockaddr_in last_from_{};     ///< udp://: sender of the previous datagram (receive thread only)
  bool closed_ = false;         ///< TCP, serial: the connection closed or the port went away; not yet reopened
  ParserStats stats_;
  /// Signing changes asked for from another thread, applied by the receive thread (which
  /// alone touches parser_) before its next datagram; guarded by mutex_.
  std::optional<SigningKey> pending_key_;
  std::optional<bool> pending_required_;
  std::thread thread_;
};

struct OpenResult {
  std::unique_ptr<Link> link;  ///< set on success
  std::string error;           ///< why it could not be opened, with the URL
};

}  // namespace eamos::mavlink
