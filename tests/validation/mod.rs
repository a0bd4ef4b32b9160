//! Layers 2 and 3 on the shipped cases, in one test binary so that the harness runs the long
//! validation runs side by side (on a software adapter each is mostly one core's work).
//! The modules name their experiments; docs/validation.md records the numbers they print.

mod bodies;
mod cases;
mod contact;
mod gate;
mod lobovsky;
mod open_channel;
mod plate;
mod sloshing;
mod submerged;
