//! The bus as it is, before anything is configured (`motion-io scan
//! --interface IF [--json]`, IgH's `ethercat slaves` and `ethercat pdos` in
//! one): every SubDevice with its position, name, identity and DC support;
//! for a CiA 402 drive (0x1000 device type 402) the objects it has, its
//! touch probe, its homing methods (0x60E3) and the PDO mapping in force;
//! which homing sequences each can serve controller-side (with the objects
//! of `motion_config::ethercat::AxisNeeds`) and drive-side (its methods);
//! and a config skeleton of the bus to start from.
//!
//! The scan brings the bus to PRE-OP (CoE), reads, and leaves it in INIT;
//! it writes nothing. It runs on the calling thread (not real time).

use std::fmt::Write as _;
use std::pin::pin;
use std::time::Duration;

use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, RetryBehaviour, SubDeviceRef, Timeouts};
use motion_config::ethercat::homing::sequences_served;
use motion_rt::now_ns;
use serde::Serialize;

use crate::capacity::{MAX_FRAMES, MAX_PDI, MAX_PDU_DATA, MAX_SUBDEVICES};
use crate::dictionary::{probe, Dictionary};
use crate::io::BusIo;
use crate::mapping::{assigned, Pdo};
use crate::report::StartupError;

/// One PDO as the scan shows it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ScannedPdo {
    /// `0x1600`.
    pub index: String,
    /// `0x6040:00/16 controlword`.
    pub entries: Vec<String>,
}

/// The homing sequences a drive can serve.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Sequences {
    /// Homed by the controller (the sequences' spellings).
    pub controller: Vec<String>,
    /// Homed by the drive (sequence, direction and method).
    pub drive: Vec<String>,
}

/// One SubDevice.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ScannedSubDevice {
    pub position: usize,
    pub name: String,
    pub vendor_id: u32,
    pub product_id: u32,
    pub revision: u32,
    pub serial: u32,
    /// Distributed clocks (SYNC0).
    pub dc: bool,
    /// It answers CoE (SDO) requests.
    pub coe: bool,
    /// 0x1000 device type names CiA 402 (a drive).
    pub cia402: bool,
    /// 0x1008, if it has one.
    pub device_name: Option<String>,
    /// The CiA 402 objects it has (`0x6040`, …).
    pub objects: Vec<String>,
    pub touch_probe: bool,
    /// 0x60E3, if it has one.
    pub homing_methods: Option<Vec<i8>>,
    pub rx_pdos: Vec<ScannedPdo>,
    pub tx_pdos: Vec<ScannedPdo>,
    pub sequences: Sequences,
}

/// The bus.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct ScanReport {
    pub interface: String,
    pub subdevices: Vec<ScannedSubDevice>,
    /// A config skeleton of the bus (TOML).
    pub config: String,
}

/// The sequences a drive with `d` can serve controller-side.
pub fn controller_sequences(d: &Dictionary) -> Vec<String> {
    let has = |i: &[u16]| i.iter().all(|&x| d.has(x));
    let core = has(&[0x6040, 0x6041, 0x6064, 0x607A]);
    if !core {
        return Vec::new();
    }
    let probe = has(&[0x60B8, 0x60B9, 0x60BA]);
    let switch = d.has(0x60FD);
    let torque = d.has(0x6077) && (has(&[0x60E0, 0x60E1]) || d.has(0x6072));
    let mut out = vec!["immediate".to_string()];
    for (name, ok) in [
        ("switch", switch),
        ("marker", probe),
        ("switch_then_marker", switch && probe),
        ("torque", torque),
        ("torque_then_marker", torque && probe),
    ] {
        if ok {
            out.push(name.into());
        }
    }
    if has(&[0x60B8, 0x60B9, 0x60BC, 0x60BD]) && switch {
        out.push("registration (a switch latched by touch probe 2)".into());
    }
    out
}

fn pdos(list: &[Pdo]) -> Vec<ScannedPdo> {
    list.iter()
        .map(|p| ScannedPdo {
            index: format!("{:#06X}", p.index),
            entries: p
                .entries
                .iter()
                .map(|e| {
                    format!(
                        "{:#06X}:{:02X}/{} {}",
                        e.index,
                        e.sub,
                        e.bits,
                        crate::objects::object_name(e.index)
                    )
                })
                .collect(),
        })
        .collect()
}

/// What a SubDevice's CoE says (nothing without a mailbox).
async fn read_coe<S>(sd: &SubDeviceRef<'_, S>, s: &mut ScannedSubDevice)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let Ok(device_type) = sd.sdo_read::<u32>(0x1000, 0).await else {
        return;
    };
    s.coe = true;
    s.cia402 = device_type & 0xFFFF == 402;
    s.device_name = sd
        .sdo_read::<heapless::String<96>>(0x1008, 0)
        .await
        .ok()
        .map(|n| n.as_str().to_string());
    if let Ok(d) = probe(sd).await {
        s.objects = d.cia402_objects();
        s.touch_probe = d.has(0x60B8) && d.has(0x60B9);
        s.homing_methods = d.homing_methods.clone();
        s.sequences = Sequences {
            controller: controller_sequences(&d),
            drive: d
                .homing_methods
                .as_deref()
                .map(sequences_served)
                .unwrap_or_default(),
        };
    }
    if let (Ok(rx), Ok(tx)) = (assigned(sd, 0x1C12).await, assigned(sd, 0x1C13).await) {
        s.rx_pdos = pdos(&rx);
        s.tx_pdos = pdos(&tx);
    }
}

/// Scans the bus on `interface` (needs CAP_NET_RAW), within `timeout`.
pub fn scan(interface: &str, timeout: Duration) -> Result<ScanReport, StartupError> {
    let storage: Box<PduStorage<MAX_FRAMES, MAX_PDU_DATA>> = Box::new(PduStorage::new());
    let (tx, rx, pdu_loop) = storage
        .try_split()
        .map_err(|_| StartupError("frame storage already in use".into()))?;
    let md = MainDevice::new(
        pdu_loop,
        Timeouts {
            state_transition: Duration::from_secs(5),
            pdu: Duration::from_millis(100),
            eeprom: Duration::from_millis(100),
            wait_loop_delay: Duration::from_micros(200),
            mailbox_echo: Duration::from_millis(500),
            mailbox_response: Duration::from_secs(2),
        },
        MainDeviceConfig {
            dc_static_sync_iterations: 0,
            retry_behaviour: RetryBehaviour::Count(2),
        },
    );
    let mut io = BusIo::new(interface, tx, rx).map_err(|e| {
        StartupError(format!(
            "cannot open a raw socket on {interface}: {e} (needs CAP_NET_RAW and an existing \
             interface)"
        ))
    })?;
    let work = async {
        let group = md
            .init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercrab::std::ethercat_now)
            .await
            .map_err(|e| StartupError(format!("bus initialisation on {interface} failed: {e}")))?;
        let mut out = Vec::new();
        for (i, sd) in group.iter(&md).enumerate() {
            let id = sd.identity();
            let mut s = ScannedSubDevice {
                position: i,
                name: sd.name().to_string(),
                vendor_id: id.vendor_id,
                product_id: id.product_id,
                revision: id.revision,
                serial: id.serial,
                dc: sd.dc_support().enhanced(),
                coe: false,
                cia402: false,
                device_name: None,
                objects: Vec::new(),
                touch_probe: false,
                homing_methods: None,
                rx_pdos: Vec::new(),
                tx_pdos: Vec::new(),
                sequences: Sequences::default(),
            };
            read_coe(&sd, &mut s).await;
            out.push(s);
        }
        let _ = group.into_init(&md).await;
        Ok::<_, StartupError>(out)
    };
    let fut = pin!(work);
    let subdevices = io
        .run(fut, Some(now_ns() + timeout.as_nanos() as u64), 200_000)
        .ok_or_else(|| {
            StartupError(format!(
                "the scan did not finish within {} s",
                timeout.as_secs()
            ))
        })??;
    if subdevices.is_empty() {
        return Err(StartupError(format!(
            "no SubDevice answers on {interface} (cable, interface, link up?)"
        )));
    }
    let config = skeleton(interface, &subdevices);
    Ok(ScanReport {
        interface: interface.to_string(),
        subdevices,
        config,
    })
}

/// A config skeleton of the bus: one `[[io]]`, one `[[axis]]` per drive.
pub fn skeleton(interface: &str, subs: &[ScannedSubDevice]) -> String {
    let mut t = format!(
        "# motion-io scan --interface {interface}: {} SubDevice(s). A skeleton: name the \
         axes, set\n# their counts_per_unit and homing (see the README's EtherCAT \
         section).\n\n[[io]]\nname = \"bus0\"\nspawn = \"supervisor\"\nbackend = \
         \"ethercat\"\ninterface = \"{interface}\"\n",
        subs.len()
    );
    for s in subs.iter().filter(|s| s.cia402) {
        let _ = write!(
            t,
            "\n[[axis]]\n# SubDevice {} {:?}: vendor {:#010x} product {:#010x} rev {}, DC {}\n\
             # controller-side homing: {}\n# drive-side homing (drive_homing = true): {}\n\
             name = \"A{}\"\nio = \"bus0\"\nethercat_position = {}\ncounts_per_unit = 1.0\n\
             home_sequence = \"immediate\"\n",
            s.position,
            s.name,
            s.vendor_id,
            s.product_id,
            s.revision,
            if s.dc { "yes" } else { "no" },
            s.sequences.controller.join(", "),
            if s.sequences.drive.is_empty() {
                "no standard method listed in 0x60E3".to_string()
            } else {
                s.sequences.drive.join(", ")
            },
            s.position,
            s.position
        );
    }
    t
}

impl ScanReport {
    /// The scan as text (`motion-io scan`).
    pub fn text(&self) -> String {
        let mut t = format!(
            "EtherCAT on {}: {} SubDevice(s)\n",
            self.interface,
            self.subdevices.len()
        );
        for s in &self.subdevices {
            let _ = writeln!(
                t,
                "\nSubDevice {} {:?}{}: vendor {:#010x} product {:#010x} rev {} serial {}, DC {}, \
                 {}",
                s.position,
                s.name,
                s.device_name
                    .as_ref()
                    .map_or(String::new(), |n| format!(" ({n})")),
                s.vendor_id,
                s.product_id,
                s.revision,
                s.serial,
                if s.dc { "yes" } else { "no" },
                match (s.coe, s.cia402) {
                    (true, true) => "CiA 402 drive",
                    (true, false) => "CoE, not CiA 402",
                    _ => "no CoE",
                }
            );
            if !s.cia402 {
                continue;
            }
            let _ = writeln!(t, "  objects: {}", s.objects.join(" "));
            let _ = writeln!(
                t,
                "  touch probe: {}; homing methods (0x60E3): {}",
                if s.touch_probe { "yes" } else { "no" },
                s.homing_methods
                    .as_ref()
                    .map_or("none listed".to_string(), |m| format!("{m:?}"))
            );
            for (dir, list) in [("RxPDO", &s.rx_pdos), ("TxPDO", &s.tx_pdos)] {
                for p in list {
                    let _ = writeln!(t, "  {dir} {} in force: {}", p.index, p.entries.join(", "));
                }
            }
            let _ = writeln!(
                t,
                "  homes controller-side: {}",
                s.sequences.controller.join(", ")
            );
            let _ = writeln!(
                t,
                "  homes drive-side: {}",
                if s.sequences.drive.is_empty() {
                    "no standard method".to_string()
                } else {
                    s.sequences.drive.join(", ")
                }
            );
        }
        let _ = write!(t, "\nConfig skeleton:\n\n{}", self.config);
        t
    }
}
