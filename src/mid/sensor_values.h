#pragma once
// A drone state's sensor readings by name ("Sensor1" … "SensorN"), in name order like the
// std::map it replaces, held in one flat array: an adapter builds a state at every motion
// step (20 Hz per drone), and a map cost one allocation per sensor per step (a third of a
// 1,000-drone run's CPU); copying this costs one.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace eamos::mid {

class SensorValues {
 public:
  using value_type = std::pair<std::string, double>;
  using iterator = std::vector<value_type>::iterator;
  using const_iterator = std::vector<value_type>::const_iterator;

  iterator begin() { return v_.begin(); }
  iterator end() { return v_.end(); }
  const_iterator begin() const { return v_.begin(); }
  const_iterator end() const { return v_.end(); }
  std::size_t size() const { return v_.size(); }
  bool empty() const { return v_.empty(); }
  void clear() { v_.clear(); }
  void reserve(std::size_t n) { v_.reserve(n); }

  const_iterator find(const std::string& name) const {
    auto it = lower(name);
    return it != v_.end() && it->first == name ? it : v_.end();
  }
  iterator find(const std::string& name) {
    auto it = lower(name);
    return it != v_.end() && it->first == name ? v_.begin() + (it - v_.cbegin()) : v_.end();
  }
  std::size_t count(const std::string& name) const { return find(name) == end() ? 0 : 1; }
  double at(const std::string& name) const {
    auto it = find(name);
    if (it == end()) throw std::out_of_range("no sensor " + name);
    return it->second;
  }
  double& operator[](const std::string& name) {
    auto it = lower(name);
    if (it != v_.end() && it->first == name) return v_[it - v_.cbegin()].second;
    return v_.insert(it, {name, 0.0})->second;
  }
  /// Adds `name` unless present (as std::map's). Names added in order go to the back at once.
  iterator emplace_hint(const_iterator, const std::string& name, double value) {
    if (v_.empty() || v_.back().first < name) {
      v_.emplace_back(name, value);
      return v_.end() - 1;
    }
    auto it = lower(name);
    if (it != v_.end() && it->first == name) return v_.begin() + (it - v_.cbegin());
    return v_.insert(it, {name, value});
  }
  bool operator==(const SensorValues& o) const { return v_ == o.v_; }

 private:
  const_iterator lower(const std::string& name) const {
    return std::lower_bound(v_.begin(), v_.end(), name,
                            [](const value_type& e, const std::string& n) { return e.first < n; });
  }
  std::vector<value_type> v_;
};

}  // namespace eamos::mid
