within GearTwin;
package Sensors "Transfer paths from the bearing pedestals to the casing accelerometers"
end Sensors;
