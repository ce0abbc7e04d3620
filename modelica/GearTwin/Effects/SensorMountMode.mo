within GearTwin.Effects;
block SensorMountMode "A structural mode between the bearing pedestal and the accelerometer (casing panel, sensor mount)"
  parameter Real frequency(unit = "Hz", min = 300, max = 4800) = 2500 "Natural frequency of the mode";
  parameter Real damping_ratio(min = 0.005, max = 0.1) = 0.02 "Modal damping ratio";
  parameter Real participation(min = 0, max = 3) = 1 "Share of the modal response seen by the sensor (0: rigid mount, 1: sensor on the modal mass)";
  input Real base_acceleration(unit = "m/s2") "Acceleration reaching the sensor's mount along its axis (the pedestal's, or the transfer path's output)";
  output Real extra_acceleration(unit = "m/s2") "Acceleration the mode adds at the sensor";
  Real deflection(unit = "m", start = 0) "Modal deflection relative to the pedestal";
  Real deflection_rate(unit = "m/s", start = 0) "Its rate";
  Real relative_acceleration(unit = "m/s2") "Acceleration of the modal mass relative to the pedestal";
equation
  relative_acceleration = -(2 * GearTwin.pi * frequency) ^ 2 * deflection - 2 * damping_ratio * 2 * GearTwin.pi * frequency * deflection_rate - base_acceleration;
  der(deflection) = deflection_rate;
  der(deflection_rate) = relative_acceleration;
  extra_acceleration = participation * relative_acceleration;
end SensorMountMode;
