within GearTwin;
block TiltingCasingWalls "Casing wall modes that reach each bearing housing in both directions: a wall that bends moves a housing along it and tilts it, in mass-normalised modal coordinates"
  // Each wall mode k moves the bearing housings by a fixed shape: reach_input_x[k] * q[k] horizontally
  // at the input-shaft housing, reach_input_y[k] * q[k] vertically, and the same at the output-shaft
  // housing. A wall under a housing bends (moving it along the wall's normal) and rotates where the
  // housing stands on it (moving the shaft centre, a lever arm away, across the normal), so a mode
  // reaches both directions. The forces on the housings drive the mode through the same shape (the
  // generalised force is the shape times the force), so the coupling is symmetric by construction.
  // q[k] is mass-normalised (m.sqrt(kg)); the reaches are in 1/sqrt(kg). The modes are elastic modes
  // of the casing about its rigid-body motion (mean axes): the rigid casing keeps taking the whole
  // bearing force.
  parameter Real frequency[4](each unit = "Hz", each min = 0) "Natural frequency of each wall mode";
  parameter Real damping[4](each min = 0) "Damping ratio of each wall mode";
  parameter Real reach_input_x[4] "Horizontal displacement of the input-shaft housing per unit modal coordinate of each mode (1/sqrt(kg))";
  parameter Real reach_input_y[4] "Vertical displacement of the input-shaft housing per unit modal coordinate (1/sqrt(kg))";
  parameter Real reach_output_x[4] "Horizontal displacement of the output-shaft housing per unit modal coordinate (1/sqrt(kg))";
  parameter Real reach_output_y[4] "Vertical displacement of the output-shaft housing per unit modal coordinate (1/sqrt(kg))";
  input Real force[4](each unit = "N") "Force of the pedestals on each housing: input x, input y, output x, output y";
  output Real displacement[4](each unit = "m") "Displacement of each housing by the wall modes: input x, input y, output x, output y";
  output Real velocity[4](each unit = "m/s") "Its rate";
  output Real acceleration[4](each unit = "m/s2") "Its acceleration";
  Real q[4](each start = 0, each nominal = 1e-7) "Mass-normalised modal displacement of each wall mode (m.sqrt(kg))";
  Real qd[4](each start = 0, each nominal = 1e-4) "Its rate (m.sqrt(kg)/s)";
equation
  der(q) = qd;
  der(qd) = {-(2 * GearTwin.pi * frequency[k]) ^ 2 * q[k] - 2 * damping[k] * 2 * GearTwin.pi * frequency[k] * qd[k] + reach_input_x[k] * force[1] + reach_input_y[k] * force[2] + reach_output_x[k] * force[3] + reach_output_y[k] * force[4] for k in 1:4};
  displacement = {sum(reach_input_x[k] * q[k] for k in 1:4), sum(reach_input_y[k] * q[k] for k in 1:4), sum(reach_output_x[k] * q[k] for k in 1:4), sum(reach_output_y[k] * q[k] for k in 1:4)};
  velocity = {sum(reach_input_x[k] * qd[k] for k in 1:4), sum(reach_input_y[k] * qd[k] for k in 1:4), sum(reach_output_x[k] * qd[k] for k in 1:4), sum(reach_output_y[k] * qd[k] for k in 1:4)};
  acceleration = {sum(reach_input_x[k] * der(qd[k]) for k in 1:4), sum(reach_input_y[k] * der(qd[k]) for k in 1:4), sum(reach_output_x[k] * der(qd[k]) for k in 1:4), sum(reach_output_y[k] * der(qd[k]) for k in 1:4)};
end TiltingCasingWalls;
