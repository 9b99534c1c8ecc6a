//! `ecat-emu`: a test fixture emulating a chain of EtherCAT SubDevices (CiA 402
//! servo drives) on a raw socket. Never a dependency of product crates.
