within GearTwin.Sensors;
block CasingAccelerometer "A casing accelerometer between two bearing pedestals: casing panel modes, a mount resonance and a sensitivity error in its path"
  // The casing section that carries the sensor moves with the two pedestals of its shaft: the
  // sensor's base sees their accelerations (along its axis) mixed by its position. The casing
  // wall between the pedestals and the sensor has modes of its own (panels): each is a
  // base-excited oscillator whose relative motion the sensor picks up by its participation (0:
  // the sensor sits on a node, or the panel is absent). The casing is light beside the pedestals,
  // so its modes do not act back on the gearbox. On its mount the sensor is a small mass on a
  // spring: one more base-excited mode (a stud on a stiff casing puts it far above the band).
  // The whole chain reads with a gain (sensitivity and amplifier error).
  parameter Real position(min = 0, max = 1) = 0 "Where between the near pedestal (0) and the far one (1)";
  parameter Real gain(min = 0.1, max = 10) = 1 "Sensitivity of the measuring chain relative to its nominal value";
  parameter Real panel_frequency[3](each unit = "Hz", each min = 50, each max = 20000) = {1000, 2000, 3000} "Natural frequencies of the casing panel modes in the path";
  parameter Real panel_damping[3](each min = 0.002, each max = 0.3) = {0.02, 0.02, 0.02} "Their damping ratios";
  parameter Real panel_participation[3](each min = 0, each max = 10) = {0, 0, 0} "How much of each panel mode the sensor sees (0: none)";
  parameter Real mount_frequency(unit = "Hz", min = 300, max = 50000) = 20000 "Resonance of the sensor on its mount";
  parameter Real mount_damping(min = 0.005, max = 0.3) = 0.05 "Damping ratio of that resonance";
  input Real near_acceleration(unit = "m/s2") "Acceleration of the near pedestal along the sensor axis";
  input Real far_acceleration(unit = "m/s2") "Acceleration of the far pedestal along the sensor axis";
  output Real acceleration(unit = "m/s2") "What the sensor reads";
  Real base_acceleration(unit = "m/s2") "Acceleration of the casing at the pedestals' line under the sensor";
  Real panel_deflection[3](each unit = "m", each start = 0) "Modal deflection of each panel mode relative to the base";
  Real panel_rate[3](each unit = "m/s", each start = 0) "Its rate";
  Real panel_acceleration[3](each unit = "m/s2") "Acceleration of each panel mode relative to the base";
  Real wall_acceleration(unit = "m/s2") "Acceleration of the casing wall under the sensor";
  Real deflection(unit = "m", start = 0) "Deflection of the mount";
  Real deflection_rate(unit = "m/s", start = 0) "Its rate";
  Real relative_acceleration(unit = "m/s2") "Acceleration of the sensor relative to the casing wall";
equation
  base_acceleration = (1 - position) * near_acceleration + position * far_acceleration;
  panel_acceleration = {-(2 * GearTwin.pi * panel_frequency[i]) ^ 2 * panel_deflection[i] - 2 * panel_damping[i] * 2 * GearTwin.pi * panel_frequency[i] * panel_rate[i] - base_acceleration for i in 1:3};
  der(panel_deflection) = panel_rate;
  der(panel_rate) = panel_acceleration;
  wall_acceleration = base_acceleration + sum(panel_participation[i] * panel_acceleration[i] for i in 1:3);
  relative_acceleration = -(2 * GearTwin.pi * mount_frequency) ^ 2 * deflection - 2 * mount_damping * 2 * GearTwin.pi * mount_frequency * deflection_rate - wall_acceleration;
  der(deflection) = deflection_rate;
  der(deflection_rate) = relative_acceleration;
  acceleration = gain * (wall_acceleration + relative_acceleration);
end CasingAccelerometer;
