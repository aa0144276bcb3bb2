//! Flash and RAM use of the firmware ELF, read from its section headers (no
//! binutils needed, so it works with rust-lld builds too).
//!
//! Sections are counted as Berkeley `size` does: allocated, read-only →
//! text; allocated, writable, with contents → data (stored in flash, copied
//! to RAM at reset); allocated without contents (NOBITS) → bss. Sections in
//! the CCM RAM region of memory.x are counted apart as ccm.
//! flash = text + data, RAM = data + bss (the stack comes on top).

use std::fmt::Write as _;

/// One allocated section of the ELF.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Section {
    pub name: String,
    pub addr: u32,
    pub size: u32,
    pub writable: bool,
    pub nobits: bool,
}

const SHT_NOBITS: u32 = 8;
const SHF_WRITE: u32 = 0x1;
const SHF_ALLOC: u32 = 0x2;

/// The allocated (loaded or reserved) sections of a 32-bit little-endian ELF.
pub fn section_sizes(elf: &[u8]) -> Result<Vec<Section>, String> {
    if elf.len() < 52 || &elf[..4] != b"\x7fELF" {
        return Err("no ELF header".into());
    }
    if elf[4] != 1 || elf[5] != 1 {
        return Err("not a 32-bit little-endian ELF".into());
    }
    let u16_at = |off: usize| -> Result<u32, String> {
        elf.get(off..off + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]) as u32)
            .ok_or_else(|| format!("truncated at {off:#x}"))
    };
    let u32_at = |off: usize| -> Result<u32, String> {
        elf.get(off..off + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("truncated at {off:#x}"))
    };
    let shoff = u32_at(0x20)? as usize;
    let shentsize = u16_at(0x2e)? as usize;
    let shnum = u16_at(0x30)? as usize;
    let shstrndx = u16_at(0x32)? as usize;
    if shentsize < 40 || shstrndx >= shnum {
        return Err("bad section header table".into());
    }
    let header = |i: usize| shoff + i * shentsize;
    let strtab = u32_at(header(shstrndx) + 16)? as usize;
    let name_at = |off: u32| -> String {
        let start = strtab + off as usize;
        let bytes = elf.get(start..).unwrap_or_default();
        let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
        String::from_utf8_lossy(&bytes[..end]).into_owned()
    };

    let mut sections = Vec::new();
    for i in 1..shnum {
        let h = header(i);
        let flags = u32_at(h + 8)?;
        let size = u32_at(h + 20)?;
        if flags & SHF_ALLOC == 0 || size == 0 {
            continue;
        }
        sections.push(Section {
            name: name_at(u32_at(h)?),
            addr: u32_at(h + 12)?,
            size,
            writable: flags & SHF_WRITE != 0,
            nobits: u32_at(h + 4)? == SHT_NOBITS,
        });
    }
    Ok(sections)
}

/// A MEMORY region of the linker script.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Region {
    pub name: String,
    pub origin: u32,
    pub length: u32,
}

impl Region {
    fn contains(&self, addr: u32) -> bool {
        addr >= self.origin && (addr - self.origin) < self.length
    }
}

/// The regions of a memory.x MEMORY block, e.g.
/// `FLASH : ORIGIN = 0x08000000, LENGTH = 768K`. Lines it cannot read are
/// skipped; the sizes report then leaves out the percentages.
pub fn parse_memory_x(text: &str) -> Vec<Region> {
    let mut plain = String::new();
    let mut rest = text;
    while let Some(start) = rest.find("/*") {
        plain.push_str(&rest[..start]);
        rest = match rest[start..].find("*/") {
            Some(end) => &rest[start + end + 2..],
            None => "",
        };
    }
    plain.push_str(rest);

    plain
        .lines()
        .filter_map(|line| {
            let (name, spec) = line.split_once(':')?;
            let name = name.split_whitespace().next()?.to_string();
            let value = |key: &str| -> Option<u32> {
                let after = spec.split_once(key)?.1.trim_start().strip_prefix('=')?;
                parse_number(after.split(',').next()?.trim())
            };
            Some(Region {
                origin: value("ORIGIN")?,
                length: value("LENGTH")?,
                name,
            })
        })
        .collect()
}

fn parse_number(s: &str) -> Option<u32> {
    let (digits, scale) = match s.as_bytes().last()? {
        b'K' | b'k' => (&s[..s.len() - 1], 1024),
        b'M' | b'm' => (&s[..s.len() - 1], 1024 * 1024),
        _ => (s, 1),
    };
    let n = match digits
        .strip_prefix("0x")
        .or_else(|| digits.strip_prefix("0X"))
    {
        Some(hex) => u32::from_str_radix(hex, 16).ok()?,
        None => digits.parse().ok()?,
    };
    n.checked_mul(scale)
}

/// Totals in the categories of Berkeley `size`, plus CCM.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Usage {
    pub text: u64,
    pub data: u64,
    pub bss: u64,
    pub ccm: u64,
}

impl Usage {
    pub fn classify(sections: &[Section], regions: &[Region]) -> Usage {
        let ccm = regions.iter().find(|r| r.name == "CCMRAM");
        let mut usage = Usage::default();
        for s in sections {
            let size = s.size as u64;
            if ccm.is_some_and(|r| r.contains(s.addr)) {
                usage.ccm += size;
            } else if s.nobits {
                usage.bss += size;
            } else if s.writable {
                usage.data += size;
            } else {
                usage.text += size;
            }
        }
        usage
    }

    pub fn flash(&self) -> u64 {
        self.text + self.data
    }

    pub fn ram(&self) -> u64 {
        self.data + self.bss
    }

    /// The size table and the use of each region, as printed by the xtask.
    pub fn report(&self, regions: &[Region]) -> String {
        let of = |name: &str, used: u64| -> String {
            match regions.iter().find(|r| r.name == name) {
                Some(r) => format!(
                    "{used:>7} B of {:>7} B ({:.1}%)",
                    r.length,
                    100.0 * used as f64 / r.length as f64
                ),
                None => format!("{used:>7} B"),
            }
        };
        let mut out = String::new();
        let _ = writeln!(out, "{:>9} {:>9} {:>9} {:>9}", "text", "data", "bss", "ccm");
        let _ = writeln!(
            out,
            "{:>9} {:>9} {:>9} {:>9}",
            self.text, self.data, self.bss, self.ccm
        );
        let _ = writeln!(out, "flash (text+data): {}", of("FLASH", self.flash()));
        let _ = writeln!(out, "RAM   (data+bss):  {} + stack", of("RAM", self.ram()));
        if self.ccm > 0 {
            let _ = writeln!(out, "CCM RAM:           {}", of("CCMRAM", self.ccm));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal ELF32 LE with the given (name, type, flags, addr, size)
    /// sections after the null section, and .shstrtab last.
    fn tiny_elf(sections: &[(&str, u32, u32, u32, u32)]) -> Vec<u8> {
        let mut strtab = vec![0u8];
        let mut names = Vec::new();
        for (name, ..) in sections.iter().chain([&(".shstrtab", 3, 0, 0, 0)]) {
            names.push(strtab.len() as u32);
            strtab.extend_from_slice(name.as_bytes());
            strtab.push(0);
        }
        let strtab_off = 52u32;
        let shoff = strtab_off + strtab.len() as u32;
        let shnum = sections.len() as u16 + 2;
        let mut elf = vec![0u8; 52];
        elf[..6].copy_from_slice(b"\x7fELF\x01\x01");
        elf[0x20..0x24].copy_from_slice(&shoff.to_le_bytes());
        elf[0x2e..0x30].copy_from_slice(&40u16.to_le_bytes());
        elf[0x30..0x32].copy_from_slice(&shnum.to_le_bytes());
        elf[0x32..0x34].copy_from_slice(&(shnum - 1).to_le_bytes());
        elf.extend_from_slice(&strtab);
        elf.extend_from_slice(&[0u8; 40]);
        let strtab_header = (
            names[sections.len()],
            3,
            0,
            0,
            strtab_off,
            strtab.len() as u32,
        );
        for (i, &(_, ty, flags, addr, size)) in sections.iter().enumerate() {
            for field in [names[i], ty, flags, addr, 0, size, 0, 0, 4, 0] {
                elf.extend_from_slice(&field.to_le_bytes());
            }
        }
        let (n, ty, flags, addr, off, size) = strtab_header;
        for field in [n, ty, flags, addr, off, size, 0, 0, 1, 0] {
            elf.extend_from_slice(&field.to_le_bytes());
        }
        elf
    }

    #[test]
    fn counts_like_berkeley_size_with_ccm_apart() {
        const PROGBITS: u32 = 1;
        const AX: u32 = SHF_ALLOC | 0x4;
        const WA: u32 = SHF_ALLOC | SHF_WRITE;
        let elf = tiny_elf(&[
            (".vector_table", PROGBITS, SHF_ALLOC, 0x0800_0000, 1024),
            (".text", PROGBITS, AX, 0x0800_0400, 3000),
            (".data", PROGBITS, WA, 0x2000_0000, 16),
            (".bss", SHT_NOBITS, WA, 0x2000_0010, 400),
            (".ccmram", SHT_NOBITS, WA, 0x1000_0000, 8192),
            (".debug_info", PROGBITS, 0, 0, 99999),
        ]);
        let sections = section_sizes(&elf).unwrap();
        assert_eq!(sections.len(), 5, "{sections:?}");
        assert_eq!(sections[1].name, ".text");
        let regions = parse_memory_x(include_str!("../../memory.x"));
        let usage = Usage::classify(&sections, &regions);
        assert_eq!(
            usage,
            Usage {
                text: 4024,
                data: 16,
                bss: 400,
                ccm: 8192
            }
        );
        assert_eq!((usage.flash(), usage.ram()), (4040, 416));
        assert!(usage.report(&regions).contains("8192 B of   65536 B"));
    }

    #[test]
    fn reads_the_regions_of_the_workspace_memory_x() {
        let regions = parse_memory_x(include_str!("../../memory.x"));
        let find = |n: &str| regions.iter().find(|r| r.name == n).cloned().unwrap();
        assert_eq!(find("FLASH").origin, 0x0800_0000);
        // 1 MB minus the two 128 KB checkpoint sectors.
        assert_eq!(find("FLASH").length, 768 * 1024);
        assert_eq!(find("CHECKPOINT").origin, 0x080C_0000);
        assert_eq!(
            find("CHECKPOINT").origin + find("CHECKPOINT").length,
            0x0810_0000
        );
        assert_eq!(find("RAM").length, 128 * 1024);
        assert_eq!(
            (find("CCMRAM").origin, find("CCMRAM").length),
            (0x1000_0000, 65536)
        );
    }

    #[test]
    fn rejects_what_is_not_an_elf32() {
        assert!(section_sizes(b"not an elf at all").is_err());
        assert!(section_sizes(&[0x7f, b'E', b'L', b'F', 2, 1, 0, 0]).is_err());
    }
}
