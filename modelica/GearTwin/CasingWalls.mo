within GearTwin;
block CasingWalls "Casing walls under the bearing housings: one clamped-panel bending mode per housing and direction, in mass-normalised modal coordinates"
  // Each of the four load paths (input-shaft housing horizontal and vertical, output-shaft
  // housing horizontal and vertical) is the first bending mode of the wall panel that carries it,
  // with the housing at the panel's antinode. In mass-normalised coordinates q[k] (m.sqrt(kg)) the
  // housing moves by q[k] / sqrt(modal_mass[k]) and a force F on the housing drives the mode by
  // F / sqrt(modal_mass[k]), so the modes take the bearing forces and move the housings back
  // with a symmetric coupling. The modes are elastic modes of the casing about its rigid-body
  // motion (mean axes): the rigid casing keeps taking the whole bearing force.
  parameter Real frequency[4](each unit = "Hz", each min = 0) "Natural frequency of each wall mode";
  parameter Real damping[4](each min = 0) "Damping ratio of each wall mode";
  parameter Real modal_mass[4](each unit = "kg", each min = 0) "Modal mass of each wall mode, referred to the housing";
  input Real force[4](each unit = "N") "Force of the pedestals on each housing: input x, input y, output x, output y";
  output Real displacement[4](each unit = "m") "Displacement of each housing by its wall mode";
  output Real velocity[4](each unit = "m/s") "Its rate";
  output Real acceleration[4](each unit = "m/s2") "Its acceleration";
  Real q[4](each start = 0, each nominal = 1e-7) "Mass-normalised modal displacement of each wall mode (m.sqrt(kg))";
  Real qd[4](each start = 0, each nominal = 1e-4) "Its rate (m.sqrt(kg)/s)";
equation
  der(q) = qd;
  der(qd) = {-(2 * GearTwin.pi * frequency[k]) ^ 2 * q[k] - 2 * damping[k] * 2 * GearTwin.pi * frequency[k] * qd[k] + force[k] / sqrt(modal_mass[k]) for k in 1:4};
  displacement = {q[k] / sqrt(modal_mass[k]) for k in 1:4};
  velocity = {qd[k] / sqrt(modal_mass[k]) for k in 1:4};
  acceleration = {der(qd[k]) / sqrt(modal_mass[k]) for k in 1:4};
end CasingWalls;
