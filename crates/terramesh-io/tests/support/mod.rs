pub mod faulted;
pub mod layered;
