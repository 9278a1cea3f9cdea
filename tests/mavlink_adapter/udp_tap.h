#pragma once
// A UDP relay between the adapter and a simulated vehicle that keeps a copy of every datagram,
// per direction, so a test can hand exactly what went over the wire to another decoder:
//   vehicle --udpout--> 127.0.0.1:vehicle_port [tap] ephemeral --> adapter's udp://:adapter_port
// The adapter answers its last sender, the tap's ephemeral socket, and the tap forwards that
// to wherever the vehicle last sent from. One thread, woken by a pipe to stop: no polling.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace eamos::test {

class UdpTap {
 public:
  UdpTap(uint16_t vehicle_port, uint16_t adapter_port) {
    vehicle_fd_ = udp_socket(vehicle_port);
    adapter_fd_ = udp_socket(0);
    adapter_addr_ = loopback(adapter_port);
    if (pipe(wake_) != 0) throw std::runtime_error("UdpTap: pipe failed");
    thread_ = std::thread([this] { run(); });
  }
  ~UdpTap() {
    stop();
    for (int fd : {vehicle_fd_, adapter_fd_, wake_[0], wake_[1]}) close(fd);
  }
  UdpTap(const UdpTap&) = delete;
  UdpTap& operator=(const UdpTap&) = delete;

  /// Stops relaying; what was captured stays readable.
  void stop() {
    if (!thread_.joinable()) return;
    char c = 0;
    if (write(wake_[1], &c, 1) != 1) throw std::runtime_error("UdpTap: wake failed");
    thread_.join();
  }
  std::vector<uint8_t> from_adapter() const {
    std::lock_guard lock(mutex_);
    return from_adapter_;
  }
  std::vector<uint8_t> from_vehicle() const {
    std::lock_guard lock(mutex_);
    return from_vehicle_;
  }

 private:
  static sockaddr_in loopback(uint16_t port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return a;
  }
  static int udp_socket(uint16_t port) {
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a = loopback(port);
    if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0)
      throw std::runtime_error("UdpTap: cannot bind UDP port " + std::to_string(port));
    return fd;
  }

  void run() {
    uint8_t buf[65536];
    for (;;) {
      pollfd fds[3] = {{wake_[0], POLLIN, 0}, {vehicle_fd_, POLLIN, 0}, {adapter_fd_, POLLIN, 0}};
      if (poll(fds, 3, -1) < 0) return;
      if (fds[0].revents) return;
      if (fds[1].revents & POLLIN) {
        sockaddr_in from{};
        socklen_t len = sizeof from;
        ssize_t n =
            recvfrom(vehicle_fd_, buf, sizeof buf, 0, reinterpret_cast<sockaddr*>(&from), &len);
        if (n > 0) {
          std::lock_guard lock(mutex_);
          from_vehicle_.insert(from_vehicle_.end(), buf, buf + n);
          vehicle_addr_ = from;
          has_vehicle_ = true;
          sendto(adapter_fd_, buf, static_cast<size_t>(n), 0,
                 reinterpret_cast<const sockaddr*>(&adapter_addr_), sizeof adapter_addr_);
        }
      }
      if (fds[2].revents & POLLIN) {
        ssize_t n = recv(adapter_fd_, buf, sizeof buf, 0);
        std::lock_guard lock(mutex_);
        if (n > 0 && has_vehicle_) {
          from_adapter_.insert(from_adapter_.end(), buf, buf + n);
          sendto(vehicle_fd_, buf, static_cast<size_t>(n), 0,
                 reinterpret_cast<const sockaddr*>(&vehicle_addr_), sizeof vehicle_addr_);
        }
      }
    }
  }

  int vehicle_fd_ = -1;
  int adapter_fd_ = -1;
  int wake_[2] = {-1, -1};
  sockaddr_in adapter_addr_{};
  std::thread thread_;
  mutable std::mutex mutex_;  ///< guards the captures and the vehicle's address
  std::vector<uint8_t> from_adapter_;
  std::vector<uint8_t> from_vehicle_;
  sockaddr_in vehicle_addr_{};
  bool has_vehicle_ = false;
};

}  // namespace eamos::test
