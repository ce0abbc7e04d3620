within ;
package GearTwin "Gearbox digital twin: dynamic models of the UNSW spur-gear test rig"
  constant Real pi = 3.141592653589793 "Ratio of circle circumference to diameter";
end GearTwin;
