within GearTwin;
package Excitation "Broadband excitation of a running gearbox: flank roughness and process forces (deterministic, seeded)"
end Excitation;
