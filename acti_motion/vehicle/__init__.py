"""The mobile base: the VehicleService core (`core`), its alarms, reference paths and cruise planning."""
