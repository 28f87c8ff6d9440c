//! Motor sizing (`armscope size`), design rather than diagnosis: which motor of a catalogue and which
//! gear ratio carry a motion — the screening of every candidate on the motion's exact inverse
//! dynamics and the verification runs (`screening`), and the report with its charts (`report`). The
//! catalogue of parts itself stays with the motors (`actuator::catalogue`): the motor files that
//! `run --motors` loads name its entries too, and sizing builds on the actuators, not the reverse.

pub mod screening;
mod report;
