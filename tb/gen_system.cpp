// Writes the generated system files (model/hw_system.hpp generate_system_files) of one
// configuration: the build uses it until `ranging generate` emits them itself.
#include <exception>
#include <iostream>

#include "model/hw_generator.hpp"
#include "model/hw_system.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: ranging_system_gen CONFIG.yaml OUT_DIR ORIGIN\n";
    return 2;
  }
  try {
    const auto design = ranging::design_receiver(ranging::load_receiver_config(argv[1]));
    ranging::write_hardware_files(ranging::generate_system_files(design, argv[3]), argv[2]);
  } catch (const std::exception& e) {
    std::cerr << "ranging_system_gen: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
