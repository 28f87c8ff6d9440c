//! What the Rerun and MCAP outputs share: the contact tracking their collision views draw, the
//! floors they draw, the plots' colours and torque scales, a bounded overview of a long path, the
//! recording's file, and the worker thread that writes it.

pub mod contacts;
pub mod floor_plate;
pub mod output_file;
pub mod overview;
pub mod plot_colours;
pub mod torque_axis;
pub mod worker;
