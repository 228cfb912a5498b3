#pragma once
// The one driver of every Verilator testbench (ZipCPU's TESTB<> idea): owns the context and
// the model of a module with a `clk` and a synchronous active-high `rst` port, advances whole
// clock cycles, holds reset, and traces at run time.
//   Trace: RANGING_TRACE=1 opens $RANGING_TRACE_DIR/<name>.fst at construction (the build
//   tree when that variable is unset, "." when the build defines no default); open_trace() /
//   close_trace() switch it on and off at any cycle. Without --trace-fst (VM_TRACE=0) tracing
//   is a no-op and open_trace() returns false.
//   Per cycle: set the inputs, settle() (combinational outputs now valid, sample the
//   handshakes), tick() (one rising edge, then the falling edge; 10 time units a cycle).
// Also: bit access to ports of any width, sign extension, signed writes to ports.
#include <verilated.h>
#if VM_TRACE
#include <verilated_fst_c.h>
#endif

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <type_traits>

#include "bits.hpp"

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
#if VM_TRACE
    ctx_->traceEverOn(true);  // must precede the model's construction
#endif
    top_ = std::make_unique<Top>(ctx_.get());
    top_->clk = 0;
    top_->rst = 0;
    top_->eval();
    if (trace_requested()) open_trace(trace_dir() + "/" + trace_name + ".fst");
  }
  ~Harness() {
    top_->final();
    close_trace();
  }
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;

  Top& top() { return *top_; }
  const Top& top() const { return *top_; }
  std::uint64_t cycles() const { return cycles_; }

  // Starts an FST dump into `path` (closing any open one); false when tracing is not compiled in.
  bool open_trace(const std::string& path) {
#if VM_TRACE
    close_trace();
    fst_ = std::make_unique<VerilatedFstC>();
    top_->trace(fst_.get(), 99);
    fst_->open(path.c_str());
    return fst_->isOpen();
#else
    (void)path;
    return false;
#endif
  }
  void close_trace() {
#if VM_TRACE
    if (fst_) fst_->close();
    fst_.reset();
#endif
  }
  bool tracing() const {
#if VM_TRACE
    return fst_ != nullptr;
#else
    return false;
#endif
  }

  void settle() { top_->eval(); }
  // One clock cycle: rising edge (registers update), then falling edge. Without a trace the
  // inputs set since the last eval settle in the rising edge's own eval (Verilator 5 runs the
  // input-combinational region before the clocked one), so two evals; with a trace a third
  // first, to dump the pre-edge values at their own time step.
  void tick() {
    if (!tracing()) {
      top_->clk = 1;
      top_->eval();
      top_->clk = 0;
      top_->eval();
      time_ += 10;  // the same time base as the traced path (a trace opened later continues it)
      ++cycles_;
      return;
    }
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
#if VM_TRACE
    if (fst_) fst_->dump(time_);
#endif
    time_ += 5;  // 10 time units per cycle
  }
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<Top> top_;
#if VM_TRACE
  std::unique_ptr<VerilatedFstC> fst_;
#endif
  std::uint64_t cycles_ = 0;
  std::uint64_t time_ = 0;
};

// A Harness for a module with one s_valid / m_ready stream pair: nothing offered and nothing
// accepted at construction, s_valid dropped while reset is held.
template <class Top>
class StreamHarness : public Harness<Top> {
 public:
  explicit StreamHarness(const std::string& trace_name) : Harness<Top>(trace_name) {
    this->top().s_valid = 0;
    this->top().m_ready = 0;
    this->settle();
  }
  void reset(int n = 2) {
    this->top().s_valid = 0;
    Harness<Top>::reset(n);
  }
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

// Writes a signed value into an integral port of `width` bits (two's complement).
template <class T>
void set_port(T& port, std::int64_t value, int width) {
  static_assert(std::is_integral_v<T>, "set_port: integral ports only");
  const std::uint64_t mask = width >= 64 ? ~std::uint64_t{0} : ((std::uint64_t{1} << width) - 1);
  port = static_cast<T>(static_cast<std::uint64_t>(value) & mask);
}

}  // namespace ranging::tb
