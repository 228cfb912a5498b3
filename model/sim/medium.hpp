#pragma once
// Air as a propagation medium: the speed of sound including humidity (Cramer 1993, the
// formula ISO 9613-1 users pair with it) and the ISO 9613-1 atmospheric absorption
// coefficient per frequency, plus the zero-phase FIR that applies that absorption over a
// path (so the received pulse shape changes with distance: higher frequencies lose more).
#include <vector>

namespace ranging {

struct AirConditions {
  double temperature_c = 20.0;       // [-40, 60] C
  double relative_humidity = 50.0;   // [0, 100] %
  double pressure_kpa = 101.325;     // [50, 120] kPa
};

// InputError naming medium.temperature_c / relative_humidity / pressure_kpa and the range.
void validate(const AirConditions& a);

// Cramer (1993), J. Acoust. Soc. Am. 93(5): c(t, p, x_w, x_c) with 400 ppm CO2; water-vapour
// mole fraction from the relative humidity (Davis 1992 enhancement factor and saturation
// pressure). 343.99 m/s at 20 C, 50 %, 101.325 kPa; 343.2 m/s dry.
double speed_of_sound(const AirConditions& a);

// ISO 9613-1:1993 eq. (3)-(5): pure-tone attenuation coefficient in dB/m at frequency f (Hz).
// The standard states its accuracy up to 10 kHz (+-10 %) and is widely used to ~1 MHz
// because its classical + rotational term (the f^2 term that dominates at 200 kHz) is the
// textbook one; docs/scenes.md says what this implies.
double absorption_db_per_m(double f_hz, const AirConditions& a);

// Linear-phase FIR with |H(f)| = 10^(-absorption_db_per_m(f) * distance / 20), odd length,
// centred: tap (n - 1)/2 is time 0, so applying it "centred" adds no delay. Designed by
// frequency sampling on a 4096-point grid and a Kaiser window (beta 8); length grows with the
// path so the (Gaussian-like) impulse response fits.
std::vector<double> absorption_fir(const AirConditions& a, double distance_m, double fs);

}  // namespace ranging
