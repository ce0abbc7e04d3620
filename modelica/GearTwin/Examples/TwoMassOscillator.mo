within GearTwin.Examples;
model TwoMassOscillator "Two masses on springs, one driven by an input force"
  parameter Real m1(unit = "kg", min = 0) = 1.0 "Mass 1";
  parameter Real m2(unit = "kg", min = 0) = 0.5 "Mass 2";
  parameter Real k1(unit = "N/m", min = 0) = 100.0 "Ground spring of mass 1";
  parameter Real k12(unit = "N/m", min = 0) = 50.0 "Coupling spring";
  parameter Real d1(unit = "N.s/m", min = 0) = 0.2 "Ground damper of mass 1";
  parameter Real f1(unit = "Hz") = sqrt(k1 / m1) / (2 * GearTwin.pi) "Natural frequency of mass 1 alone";
  input Real force(unit = "N", start = 0.0) "Force on mass 2";
  Real x1(unit = "m", start = 0.01, fixed = true) "Position of mass 1";
  Real v1(unit = "m/s", start = 0.0, fixed = true) "Velocity of mass 1";
  Real x2(unit = "m", start = 0.0, fixed = true) "Position of mass 2";
  Real v2(unit = "m/s", start = 0.0, fixed = true) "Velocity of mass 2";
  Real spring_force(unit = "N") "Force in the coupling spring";
  output Real a2(unit = "m/s2") "Acceleration of mass 2";
  output Real position2(unit = "m") = x2 "Position of mass 2";
equation
  spring_force = k12 * (x2 - x1);
  der(x1) = v1;
  m1 * der(v1) = -k1 * x1 - d1 * v1 + spring_force;
  der(x2) = v2;
  m2 * der(v2) = force - spring_force;
  a2 = der(v2);
  annotation(experiment(StartTime = 0, StopTime = 10, Interval = 1e-3));
end TwoMassOscillator;
