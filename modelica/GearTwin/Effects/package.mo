within GearTwin;
package Effects "Physical effects the base gearbox model lacks; each one binds to an effect hook of GearTwin.Gearbox21"
end Effects;
