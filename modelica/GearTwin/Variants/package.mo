within GearTwin;
package Variants "Base gearbox models extended with effect components (written by twin add-effect or by hand)"
end Variants;
