#include "model/dsp/correlator_headroom.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "model/base/error.hpp"

namespace ranging {

const char* bank_node_name(BankNode n) {
  switch (n) {
    case BankNode::Mixer: return "mixer B";
    case BankNode::Decimator: return "decimator Bd";
    case BankNode::ChipFir: return "chip filter accumulator F";
    case BankNode::ChipQ: return "chip filter output F_q";
    case BankNode::Combiner: return "combiner C_j";
    case BankNode::CorrQ: return "combiner output C_q";
    case BankNode::Power: return "power P_j";
    case BankNode::Weighted: return "weighted power Q_j";
    case BankNode::Energy: return "energy E";
  }
  return "?";
}

namespace {

// The sensitivity a[m] of a linear node at output sample N to y[N-m] (m < span), in units of
// y * LO (before the mixer's shift), and the output sample it was computed for.
struct Sensitivity {
  std::vector<double> a;
  std::int64_t n_out = 0;
  double l1() const {
    double s = 0;
    for (double v : a) s += std::abs(v);
    return s;
  }
};

class Linearized {
 public:
  Linearized(const CorrelatorReference& ref, const CorrelatorFixedLayout& l) : ref_(ref), l_(l) {
    // T(m) = sum_{i : 0 <= m - i D < P} g_q[i]: the chip FIR seen through the decimator.
    t_.assign(static_cast<std::size_t>((l.taps - 1) * l.decimation + l.period), 0.0);
    for (int i = 0; i < l.taps; ++i) {
      for (int p = 0; p < l.period; ++p) t_[static_cast<std::size_t>(i * l.decimation + p)] += static_cast<double>(l.taps_q[i]);
    }
  }

  // Span (samples) of the node's dependence on the input.
  std::size_t span(BankNode node) const {
    switch (node) {
      case BankNode::Mixer: return 1;
      case BankNode::Decimator: return static_cast<std::size_t>(l_.period);
      case BankNode::ChipFir:
      case BankNode::ChipQ: return t_.size();
      default: return t_.size() + static_cast<std::size_t>((l_.chips - 1) * l_.chip_samples);
    }
  }

  // The worst of the P output phases: largest L1 norm.
  Sensitivity worst(BankNode node, int code, bool imag) const {
    const std::size_t s = span(node);
    const std::int64_t d = l_.decimation;
    std::int64_t n0 = static_cast<std::int64_t>(s) - 1;
    n0 += (d - (n0 + 1) % d) % d;  // (N + 1) % D == 0: N is a decimated output
    Sensitivity best;
    for (int k = 0; k < l_.period; ++k) {
      Sensitivity c = at(node, code, imag, n0 + k * d, s);
      if (best.a.empty() || c.l1() > best.l1()) best = std::move(c);
    }
    return best;
  }

 private:
  double lo(std::int64_t n, bool imag) const {
    const std::size_t p = static_cast<std::size_t>(n % l_.period);
    return imag ? -static_cast<double>(l_.lo_sin[p]) : static_cast<double>(l_.lo_cos[p]);
  }
  double t(std::int64_t m) const {
    return m >= 0 && m < static_cast<std::int64_t>(t_.size()) ? t_[static_cast<std::size_t>(m)] : 0.0;
  }
  Sensitivity at(BankNode node, int code, bool imag, std::int64_t n_out, std::size_t s) const {
    Sensitivity r;
    r.n_out = n_out;
    r.a.assign(s, 0.0);
    for (std::size_t m = 0; m < s; ++m) {
      const auto mi = static_cast<std::int64_t>(m);
      double g = 1.0;
      if (node == BankNode::ChipFir || node == BankNode::ChipQ) {
        g = t(mi);
      } else if (node != BankNode::Mixer && node != BankNode::Decimator) {
        g = 0;
        const auto& chips = ref_.codes.at(static_cast<std::size_t>(code));
        for (int c = 0; c < l_.chips; ++c) {
          g += (chips[static_cast<std::size_t>(c)] ? 1.0 : -1.0) * t(mi - static_cast<std::int64_t>(l_.chips - 1 - c) * l_.chip_samples);
        }
      }
      r.a[m] = lo(n_out - mi, imag) * g;
    }
    return r;
  }

  const CorrelatorReference& ref_;
  const CorrelatorFixedLayout& l_;
  std::vector<double> t_;
};

std::vector<std::int64_t> sign_sequence(const Sensitivity& s, int data_bits, bool negate) {
  const std::int64_t top = (std::int64_t{1} << (data_bits - 1)) - 1, bottom = -top - 1;
  std::vector<std::int64_t> y(static_cast<std::size_t>(s.n_out + 1), 0);
  for (std::size_t m = 0; m < s.a.size(); ++m) {
    if (s.a[m] == 0) continue;
    const bool pos = (s.a[m] > 0) != negate;
    y[static_cast<std::size_t>(s.n_out) - m] = pos ? top : bottom;
  }
  return y;
}

double tap_l1(const CorrelatorFixedLayout& l) {
  double s = 0;
  for (std::int64_t g : l.taps_q) s += std::abs(static_cast<double>(g));
  return s;
}

}  // namespace

namespace {

// The worst case of a node from a resolved layout and its linearization (correlator_headroom
// drives dozens of them from one of each).
std::vector<std::int64_t> worst_case(const CorrelatorFixedLayout& l, const Linearized& lin, int data_bits, BankNode node,
                                     int code, bool imag, bool negate) {
  if (node == BankNode::Power || node == BankNode::Weighted) {
    throw InputError("correlator_worst_case: P_j and Q_j take the C_q worst case (BankNode::CorrQ)");
  }
  if (code < 0 || code >= l.codes) {
    throw InputError("correlator_worst_case: code " + std::to_string(code) + " outside [0, " +
                     std::to_string(l.codes - 1) + "]");
  }
  if (node == BankNode::Energy) {
    const std::int64_t bottom = -(std::int64_t{1} << (data_bits - 1));
    const auto d = static_cast<std::size_t>(l.decimation);
    std::size_t n = static_cast<std::size_t>(l.window);
    n += (d - n % d) % d;
    return std::vector<std::int64_t>(n, negate ? -bottom - 1 : bottom);
  }
  return sign_sequence(lin.worst(node, code, imag), data_bits, negate);
}

}  // namespace

std::vector<std::int64_t> correlator_worst_case(const CorrelatorReference& ref, const CorrelatorFixedConfig& cfg,
                                                BankNode node, int code, bool imag, bool negate) {
  const CorrelatorFixedLayout l = resolve_correlator_layout(ref, cfg);
  return worst_case(l, Linearized(ref, l), cfg.data_bits, node, code, imag, negate);
}

std::vector<BankNodeHeadroom> correlator_headroom(const CorrelatorReference& ref, const CorrelatorFixedConfig& cfg) {
  const CorrelatorFixedLayout l = resolve_correlator_layout(ref, cfg);
  const Linearized lin(ref, l);
  const double ymax = std::ldexp(1.0, cfg.data_bits - 1);
  const double ms = std::ldexp(1.0, -l.mix_shift), cs = std::ldexp(1.0, -l.chip_shift), rs = std::ldexp(1.0, -l.corr_shift);
  const double g1 = tap_l1(l);
  const double chip_limit = std::ldexp(1.0, cfg.chip_bits - 1), corr_limit = std::ldexp(1.0, cfg.corr_bits - 1);
  double lo_max = 0, lo_l1 = 0;
  for (int p = 0; p < l.period; ++p) {
    const double m = std::max(std::abs(static_cast<double>(l.lo_cos[p])), std::abs(static_cast<double>(l.lo_sin[p])));
    lo_max = std::max(lo_max, m);
  }
  for (bool im : {false, true}) {
    double s = 0;
    for (int p = 0; p < l.period; ++p) s += std::abs(static_cast<double>(im ? l.lo_sin[p] : l.lo_cos[p]));
    lo_l1 = std::max(lo_l1, s);
  }
  double w_max = 0;
  for (std::int64_t w : l.weights) w_max = std::max(w_max, static_cast<double>(w));

  auto node = [&](BankNode n, int bits, bool exact, double bound, double limit) {
    BankNodeHeadroom h;
    h.node = n;
    h.name = bank_node_name(n);
    h.bits = bits;
    h.exact = exact;
    h.bound = bound;
    h.limit = limit;
    h.headroom_bits = std::log2(limit / std::max(bound, 1e-300));
    return h;
  };
  const double f_bound_re = std::max(lin.worst(BankNode::ChipFir, 0, false).l1(), lin.worst(BankNode::ChipFir, 0, true).l1());
  const double f_bound = ymax * f_bound_re * ms + 0.5 * l.period * g1;
  // Saturating nodes report the value their input demands (headroom < 0 past the word); the
  // nodes after them see the saturated value.
  const double fq_demand = f_bound * cs + 0.5;
  double c_bound = 0;
  int c_code = 0;
  for (int j = 0; j < l.codes; ++j) {
    for (bool im : {false, true}) {
      const double b = std::min(ymax * lin.worst(BankNode::Combiner, j, im).l1() * ms * cs +
                                    l.chips * (0.5 + 0.5 * l.period * g1 * cs),
                                l.chips * chip_limit);
      if (b > c_bound) {
        c_bound = b;
        c_code = j;
      }
    }
  }
  const double cq_demand = c_bound * rs + 0.5;
  const double cq_bound = std::min(cq_demand, corr_limit);
  const double p_bound = 2 * cq_bound * cq_bound;
  std::vector<BankNodeHeadroom> out;
  out.push_back(node(BankNode::Mixer, cfg.mix_bits, false, ymax * lo_max * ms + 0.5, std::ldexp(1.0, cfg.mix_bits - 1)));
  out.push_back(node(BankNode::Decimator, l.dec_bits, true, ymax * lo_l1 * ms + 0.5 * l.period, std::ldexp(1.0, l.dec_bits - 1)));
  out.push_back(node(BankNode::ChipFir, l.fir_bits, true, f_bound, std::ldexp(1.0, l.fir_bits - 1)));
  out.push_back(node(BankNode::ChipQ, cfg.chip_bits, false, fq_demand, chip_limit));
  out.push_back(node(BankNode::Combiner, l.comb_bits, true, c_bound, std::ldexp(1.0, l.comb_bits - 1)));
  out.back().worst_code = c_code;
  out.push_back(node(BankNode::CorrQ, cfg.corr_bits, false, cq_demand, corr_limit));
  out.back().worst_code = c_code;
  out.push_back(node(BankNode::Power, l.power_bits, true, p_bound, std::ldexp(1.0, l.power_bits) - 1));
  out.push_back(node(BankNode::Weighted, l.weighted_bits, true, p_bound * w_max, std::ldexp(1.0, l.weighted_bits) - 1));
  out.push_back(node(BankNode::Energy, l.energy_bits, true, static_cast<double>(l.window) * ymax * ymax,
                     std::ldexp(1.0, l.energy_bits) - 1));

  // Measurement: each node under its worst cases in the fixed model. Exact nodes count a value
  // beyond their word as an overflow (none can occur if the layout is right); saturating nodes
  // count the model's saturations.
  auto at = [&](BankNode n) -> BankNodeHeadroom& {
    return *std::find_if(out.begin(), out.end(), [n](const BankNodeHeadroom& h) { return h.node == n; });
  };
  auto note = [](BankNodeHeadroom& h, double v) {
    h.measured = std::max(h.measured, std::abs(v));
    if (h.exact && std::abs(v) > h.limit) ++h.overflows;
  };
  auto run = [&](BankNode n, int code, bool im, bool neg) {
    const std::vector<std::int64_t> y = worst_case(l, lin, cfg.data_bits, n, code, im, neg);
    CorrelatorBankFixed bank(ref, cfg);
    for (std::int64_t v : y) {
      const bool out_ready = bank.execute(v);
      if (n == BankNode::Mixer) note(at(n), static_cast<double>(im ? bank.mix_im() : bank.mix_re()));
      if (!out_ready) continue;
      switch (n) {
        case BankNode::Mixer: break;
        case BankNode::Decimator: note(at(n), static_cast<double>(im ? bank.dec_im() : bank.dec_re())); break;
        case BankNode::ChipFir: note(at(n), static_cast<double>(im ? bank.chip_acc_im() : bank.chip_acc_re())); break;
        case BankNode::ChipQ: note(at(n), static_cast<double>(im ? bank.chip_im() : bank.chip_re())); break;
        case BankNode::Combiner:
          note(at(n), static_cast<double>((im ? bank.comb_im() : bank.comb_re())[static_cast<std::size_t>(code)]));
          break;
        case BankNode::CorrQ: {
          const auto j = static_cast<std::size_t>(code);
          note(at(n), static_cast<double>((im ? bank.corr_im() : bank.corr_re())[j]));
          note(at(BankNode::Power), static_cast<double>(bank.power()[j]));
          note(at(BankNode::Weighted), static_cast<double>(bank.weighted_power()[j]));
          break;
        }
        case BankNode::Energy: note(at(n), static_cast<double>(bank.energy())); break;
        default: break;
      }
    }
    if (n == BankNode::Mixer) at(n).overflows += bank.mix_overflow_events().total();
    if (n == BankNode::ChipQ) at(n).overflows += bank.chip_overflow_events().total();
    if (n == BankNode::CorrQ) at(n).overflows += bank.corr_overflow_events().total();
  };
  for (bool neg : {false, true}) {
    for (bool im : {false, true}) {
      for (BankNode n : {BankNode::Mixer, BankNode::Decimator, BankNode::ChipFir, BankNode::ChipQ}) run(n, 0, im, neg);
      for (int j = 0; j < l.codes; ++j) {
        run(BankNode::Combiner, j, im, neg);
        run(BankNode::CorrQ, j, im, neg);
      }
    }
    run(BankNode::Energy, 0, false, neg);
  }
  return out;
}

}  // namespace ranging
