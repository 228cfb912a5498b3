#pragma once
// Memo<Value>: results of a pure, deterministic function kept by the exact bytes of its
// arguments, so a second call with the same arguments returns a copy of the first result
// instead of computing it again (the same value bit for bit). Thread-safe (one mutex; the value
// is computed outside it, so two threads may compute the same key once each). At most
// `capacity` entries: when full it is emptied (a sweep's thousands of designs do not grow it).
// Used where one run asks the same question twice: a scene's bandpass is designed and checked
// when the scene is loaded and again when its receiver is built (model/dsp/filter_design.cpp,
// model/dsp/stability.cpp).
//   MemoKey k; k.add(spec.fs).add(order);  Memo<SosFilter> m;  m.get(k, [&] { return design(); });
#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

namespace ranging {

// The arguments' bytes (trivially copyable values without padding bytes, e.g. structs of
// doubles, and vectors of them, in order).
class MemoKey {
 public:
  template <class T>
  MemoKey& add(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&v);
    bytes_.append(p, sizeof v);
    return *this;
  }
  template <class T>
  MemoKey& add(const std::vector<T>& v) {
    add(v.size());
    for (const auto& x : v) add(x);
    return *this;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

template <class Value>
class Memo {
 public:
  explicit Memo(std::size_t capacity = 64) : capacity_(capacity) {}
  template <class Compute>
  Value get(const MemoKey& key, Compute compute) {
    {
      const std::lock_guard<std::mutex> lock(m_);
      if (auto it = map_.find(key.bytes()); it != map_.end()) return it->second;
    }
    Value v = compute();  // an exception leaves nothing behind
    const std::lock_guard<std::mutex> lock(m_);
    if (map_.size() >= capacity_) map_.clear();
    map_.emplace(key.bytes(), v);
    return v;
  }

 private:
  std::size_t capacity_;
  std::mutex m_;
  std::map<std::string, Value> map_;
};

}  // namespace ranging
