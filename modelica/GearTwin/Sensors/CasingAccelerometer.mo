within GearTwin.Sensors;
block CasingAccelerometer "A casing accelerometer between two bearing pedestals, on a mount with its own resonance, with a sensitivity error"
  // The casing section that carries the sensor moves with the two pedestals of its shaft: the
  // sensor sees their accelerations (along its axis) mixed by its position. On its mount the
  // sensor is a small mass on a spring: a base-excited mode that lifts the response near its
  // frequency (a stud on a stiff casing puts it far above the band; a bracket or a magnet brings
  // it down). The whole chain reads with a gain (sensitivity and amplifier error).
  parameter Real position(min = 0, max = 1) = 0 "Where between the near pedestal (0) and the far one (1)";
  parameter Real gain(min = 0.1, max = 10) = 1 "Sensitivity of the measuring chain relative to its nominal value";
  parameter Real mount_frequency(unit = "Hz", min = 300, max = 50000) = 20000 "Resonance of the sensor on its mount";
  parameter Real mount_damping(min = 0.005, max = 0.3) = 0.05 "Damping ratio of that resonance";
  input Real near_acceleration(unit = "m/s2") "Acceleration of the near pedestal along the sensor axis";
  input Real far_acceleration(unit = "m/s2") "Acceleration of the far pedestal along the sensor axis";
  output Real acceleration(unit = "m/s2") "What the sensor reads";
  Real base_acceleration(unit = "m/s2") "Acceleration of the casing under the sensor";
  Real deflection(unit = "m", start = 0) "Deflection of the mount";
  Real deflection_rate(unit = "m/s", start = 0) "Its rate";
  Real relative_acceleration(unit = "m/s2") "Acceleration of the sensor relative to the casing";
equation
  base_acceleration = (1 - position) * near_acceleration + position * far_acceleration;
  relative_acceleration = -(2 * GearTwin.pi * mount_frequency) ^ 2 * deflection - 2 * mount_damping * 2 * GearTwin.pi * mount_frequency * deflection_rate - base_acceleration;
  der(deflection) = deflection_rate;
  der(deflection_rate) = relative_acceleration;
  acceleration = gain * (base_acceleration + relative_acceleration);
end CasingAccelerometer;
