//! Motor sizing (`armscope size`), design rather than diagnosis: which motor of a catalogue and which
//! gear ratio carry a motion — the screening of every candidate on the motion's exact inverse
//! dynamics and the verification runs (`screening`), the report with its charts and bill of
//! materials (`report`), and the catalogue's listing for people (`catalogue_listing`, `armscope
//! catalogue`). The catalogue of parts itself stays with the motors (`actuator::catalogue`), as does
//! the thermal model (`actuator::thermal`, which `run` steps): the motor files that `run --motors`
//! loads name the catalogue's entries too, and sizing builds on the actuators, not the reverse.

pub mod catalogue_listing;
pub mod screening;
mod report;
