within ;
package GearTwin "Gearbox digital twin: dynamic models of the UNSW spur-gear test rig"
  constant Real pi = 3.141592653589793 "Ratio of circle circumference to diameter";
  annotation(version = "0.1.0", __GearTwin(author = "gear-twin developers"));
end GearTwin;
