#pragma once
// A sensor named in a case ([[sensors]], docs/case_files.md): what a lab would measure, for
// controllers (simulation/simulation.hpp) and as recorded outputs (simulation/sensors.hpp evaluates them).
#include <string>

namespace rfem {

struct SensorSpec {
  enum class Kind {
    Encoder,  ///< a joint's q and q̇ [rad or m, /s]
    Torque,   ///< a joint's torque or force, applied or required [N m or N]
    Tip,      ///< a link's tip: "deflection" (u1, u2 [m], θ [rad] in {r}), or its "position",
              ///< "velocity" or "acceleration" (absolute, in the axes of `frame`)
    Strain,   ///< a strain gauge: axial strain of the fibre at `distance` from the axis towards +`face`,
              ///< ε = M c / (E I) from the bending moment of the sde nearest `at` (tension positive)
    Imu       ///< an IMU at `at` along a link: the angular rate and specific force (a − g) of the
              ///< body it sits on, in that body's axes (what a strapdown gyro and accelerometer read)
  };
  std::string name;
  Kind kind = Kind::Encoder;
  std::string joint;       ///< Encoder, Torque
  std::string link;        ///< Tip, Strain
  std::string quantity;    ///< Tip: "deflection", "position", "velocity" or "acceleration"
  std::string frame;       ///< Tip (not deflection): "world" ({0}) or "link" ({r}; position from its origin)
  double at = 0.0;         ///< Strain, Imu: along the link [m]
  char face = 'z';         ///< Strain: 'y' (bending about z) or 'z' (bending about y)
  double distance = 0.0;   ///< Strain: from the elastic axis [m]
  double noise = 0.0;      ///< standard deviation of Gaussian noise added to each value (its unit)
  double quantum = 0.0;    ///< resolution: values rounded to multiples of it (0: none)
  long seed = 0;           ///< of the noise (reproducible)
  std::string where;       ///< "file:line: sensors.K" for messages
};

const char* to_string(SensorSpec::Kind k);

}  // namespace rfem
