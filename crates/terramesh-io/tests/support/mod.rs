pub mod layered;
