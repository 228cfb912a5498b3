#pragma once
// Generic driver for a Verilated module with a `clk` and a synchronous active-high `rst`
// port: owns the context and the model, advances whole clock cycles, and dumps an FST trace
// when the environment asks for one (RANGING_TRACE=1; the file goes to
// $RANGING_TRACE_DIR/<name>.fst, or to the build tree when that variable is unset).
// Usage per cycle: set the inputs, settle() (combinational outputs now valid, sample the
// handshakes), tick() (one rising edge). Also: bit access to ports of any width.
#include <verilated.h>
#include <verilated_fst_c.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <type_traits>

namespace ranging::tb {

inline bool trace_requested() {
  const char* e = std::getenv("RANGING_TRACE");
  return e != nullptr && std::string(e) == "1";
}

inline std::string trace_dir() {
  const char* d = std::getenv("RANGING_TRACE_DIR");
  if (d != nullptr && *d != '\0') return d;
#ifdef RANGING_TRACE_DIR
  return RANGING_TRACE_DIR;
#else
  return ".";
#endif
}

template <class Top>
class Harness {
 public:
  // trace_name: file stem of the FST dump (only written when tracing is requested).
  explicit Harness(const std::string& trace_name) : ctx_(std::make_unique<VerilatedContext>()) {
    const bool trace = trace_requested();
    if (trace) ctx_->traceEverOn(true);  // must precede the model's construction
    top_ = std::make_unique<Top>(ctx_.get());
    if (trace) {
      fst_ = std::make_unique<VerilatedFstC>();
      top_->trace(fst_.get(), 99);
      fst_->open((trace_dir() + "/" + trace_name + ".fst").c_str());
    }
    top_->clk = 0;
    top_->rst = 0;
    top_->eval();
  }
  ~Harness() {
    top_->final();
    if (fst_) fst_->close();
  }
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;

  Top& top() { return *top_; }
  std::uint64_t cycles() const { return cycles_; }

  void settle() { top_->eval(); }
  // One clock cycle: rising edge (registers update), then falling edge.
  void tick() {
    top_->eval();
    dump();
    top_->clk = 1;
    top_->eval();
    dump();
    top_->clk = 0;
    top_->eval();
    ++cycles_;
  }
  // Holds rst for `n` cycles (inputs as set by the caller), then releases it.
  void reset(int n = 2) {
    top_->rst = 1;
    for (int i = 0; i < n; ++i) tick();
    top_->rst = 0;
    settle();
  }

 private:
  void dump() {
    if (fst_) fst_->dump(time_);
    time_ += 5;  // 10 time units per cycle
  }
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<Top> top_;
  std::unique_ptr<VerilatedFstC> fst_;
  std::uint64_t cycles_ = 0;
  std::uint64_t time_ = 0;
};

// Bits [lsb, lsb+width) of a port of any width (width <= 64), zero-extended.
template <class T>
std::uint64_t port_bits(const T& v, int lsb, int width) {
  std::uint64_t r = 0;
  if constexpr (std::is_integral_v<T>) {
    r = static_cast<std::uint64_t>(v) >> lsb;
  } else {  // VlWide: 32-bit words, little-endian
    for (int b = 0; b < width; ++b) {
      const int i = lsb + b;
      const std::uint64_t bit = (v.at(static_cast<std::size_t>(i / 32)) >> (i % 32)) & 1u;
      r |= bit << b;
    }
  }
  return width >= 64 ? r : (r & ((std::uint64_t{1} << width) - 1));
}

// Two's complement value of the low `width` bits of `raw`.
inline std::int64_t sign_extend(std::uint64_t raw, int width) {
  if (width >= 64) return static_cast<std::int64_t>(raw);
  const std::uint64_t m = std::uint64_t{1} << (width - 1);
  raw &= (std::uint64_t{1} << width) - 1;
  return static_cast<std::int64_t>(raw ^ m) - static_cast<std::int64_t>(m);
}

// Writes a signed value into an integral port of `width` bits (two's complement).
template <class T>
void set_port(T& port, std::int64_t value, int width) {
  static_assert(std::is_integral_v<T>, "set_port: integral ports only");
  const std::uint64_t mask = width >= 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << width) - 1);
  port = static_cast<T>(static_cast<std::uint64_t>(value) & mask);
}

}  // namespace ranging::tb
