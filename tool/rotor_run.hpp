#pragma once
// `ranging simulate` on a rotor scene (geometry.type: rotor, model/sim/rotor.hpp): runs the
// crossings and writes DIR/summary.json ("crossings": per crossing index, t_s, h_true_m,
// h_est_m (motion-aware), h_est_paper_m (eq. 1), measurements, and the list), DIR/bursts.csv
// (every rendered burst: where in the window, Doppler, decoded, ToF error) and
// DIR/measurements.csv (every detection).
#include <string>

#include "model/sim/scene_simulator.hpp"

namespace ranging::tool {

int simulate_rotor(SceneSimulator& sim, const std::string& out, bool json, bool quiet);

}  // namespace ranging::tool
