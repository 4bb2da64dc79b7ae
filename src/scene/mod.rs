//! Scenes: a scene file ([`file`]) names an input, cameras, frames and the
//! shape cues wanted; the planner ([`planner`], pure data, testable without a
//! device) turns the cues into exactly the passes they need; the executor
//! ([`exec`]) runs those passes and nothing else, renders, and reports which
//! passes ran, how often and for how long.

pub mod exec;
pub mod file;
pub mod planner;
