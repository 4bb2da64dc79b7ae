//! Scenes: which shape cues a scene asks for, and the passes they need.
//! The planner ([`planner`]) is pure data, testable without a device; the
//! scene file and the executor that runs a plan come with the renderer
//! integration.

pub mod planner;
