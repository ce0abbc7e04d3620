within GearTwin;
package Examples "Small models that exercise the FMU builder"
end Examples;
