//! Flash and RAM use of the firmware ELF, read from its section headers and
//! symbol table (no binutils needed, so it works with rust-lld builds too).
//!
//! Sections are counted as Berkeley `size` does: allocated, read-only →
//! text; allocated, writable, with contents → data (stored in flash, copied
//! to RAM at reset); allocated without contents (NOBITS) → bss. Sections in
//! the CCMRAM and SDRAM regions of the linker script are counted apart, as
//! ccm and sdram. flash = text + data, RAM = data + bss (the stack comes on
//! top). The weight table's pieces are the symbols `PADA_TABLE_*` (their
//! address and size), each placed in the region that holds it.

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

/// A 32-bit little-endian ELF's bytes and its section header table, read
/// with bounds checks (a truncated file is an error, never a panic).
struct Elf32<'a> {
    elf: &'a [u8],
    shoff: usize,
    shentsize: usize,
    shnum: usize,
}

impl<'a> Elf32<'a> {
    fn open(elf: &'a [u8]) -> Result<Self, String> {
        if elf.len() < 52 || &elf[..4] != b"\x7fELF" {
            return Err("no ELF header".into());
        }
        if elf[4] != 1 || elf[5] != 1 {
            return Err("not a 32-bit little-endian ELF".into());
        }
        let mut e = Elf32 { elf, shoff: 0, shentsize: 0, shnum: 0 };
        e.shoff = e.u32_at(0x20)? as usize;
        e.shentsize = e.u16_at(0x2e)?;
        e.shnum = e.u16_at(0x30)?;
        if e.shentsize < 40 {
            return Err("bad section header table".into());
        }
        Ok(e)
    }

    fn u16_at(&self, off: usize) -> Result<usize, String> {
        self.elf
            .get(off..off + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]) as usize)
            .ok_or_else(|| format!("truncated at {off:#x}"))
    }

    fn u32_at(&self, off: usize) -> Result<u32, String> {
        self.elf
            .get(off..off + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("truncated at {off:#x}"))
    }

    /// The offset of section header `i`.
    fn header(&self, i: usize) -> usize {
        self.shoff + i * self.shentsize
    }

    /// The NUL-terminated string at `off` (empty past the end).
    fn c_str(&self, off: usize) -> &'a [u8] {
        let bytes = self.elf.get(off..).unwrap_or_default();
        let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
        &bytes[..end]
    }
}

/// The allocated (loaded or reserved) sections of a 32-bit little-endian ELF.
pub fn section_sizes(elf: &[u8]) -> Result<Vec<Section>, String> {
    let e = Elf32::open(elf)?;
    let shstrndx = e.u16_at(0x32)?;
    if shstrndx >= e.shnum {
        return Err("bad section header table".into());
    }
    let strtab = e.u32_at(e.header(shstrndx) + 16)? as usize;
    let mut sections = Vec::new();
    for i in 1..e.shnum {
        let h = e.header(i);
        let flags = e.u32_at(h + 8)?;
        let size = e.u32_at(h + 20)?;
        if flags & SHF_ALLOC == 0 || size == 0 {
            continue;
        }
        sections.push(Section {
            name: String::from_utf8_lossy(e.c_str(strtab + e.u32_at(h)? as usize)).into_owned(),
            addr: e.u32_at(h + 12)?,
            size,
            writable: flags & SHF_WRITE != 0,
            nobits: e.u32_at(h + 4)? == SHT_NOBITS,
        });
    }
    Ok(sections)
}

/// A symbol of the ELF's symbol table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Symbol {
    pub name: String,
    pub addr: u32,
    pub size: u32,
}

const SHT_SYMTAB: u32 = 2;
const SYM_LEN: usize = 16;

/// The symbols whose name starts with `prefix`, from every symbol table of
/// a 32-bit little-endian ELF (none if it has no symbol table: a stripped
/// ELF).
pub fn symbols(elf: &[u8], prefix: &str) -> Result<Vec<Symbol>, String> {
    let e = Elf32::open(elf)?;
    let mut found = Vec::new();
    for i in 1..e.shnum {
        let h = e.header(i);
        if e.u32_at(h + 4)? != SHT_SYMTAB {
            continue;
        }
        let (offset, size) = (e.u32_at(h + 16)? as usize, e.u32_at(h + 20)? as usize);
        let link = e.u32_at(h + 24)? as usize;
        if link >= e.shnum {
            return Err(format!("symbol table {i} links to section {link} of {}", e.shnum));
        }
        let strtab = e.u32_at(e.header(link) + 16)? as usize;
        for s in (offset..offset + size).step_by(SYM_LEN) {
            let name = e.c_str(strtab + e.u32_at(s)? as usize);
            if !name.starts_with(prefix.as_bytes()) {
                continue;
            }
            found.push(Symbol {
                name: String::from_utf8_lossy(name).into_owned(),
                addr: e.u32_at(s + 4)?,
                size: e.u32_at(s + 8)?,
            });
        }
    }
    found.sort_by_key(|s| s.addr);
    Ok(found)
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

/// Totals in the categories of Berkeley `size`, plus CCM and SDRAM.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Usage {
    pub text: u64,
    pub data: u64,
    pub bss: u64,
    pub ccm: u64,
    pub sdram: u64,
}

/// The region of the linker script each named region is called by.
const CCM_REGION: &str = "CCMRAM";
const SDRAM_REGION: &str = "SDRAM";

impl Usage {
    pub fn classify(sections: &[Section], regions: &[Region]) -> Usage {
        let within = |name: &str, addr: u32| regions.iter().any(|r| r.name == name && r.contains(addr));
        let mut usage = Usage::default();
        for s in sections {
            let size = s.size as u64;
            if within(CCM_REGION, s.addr) {
                usage.ccm += size;
            } else if within(SDRAM_REGION, s.addr) {
                usage.sdram += size;
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

    /// The size table, the use of each region, and where the weight table
    /// (`table`: its `PADA_TABLE_*` symbols) lies, as printed by the xtask.
    pub fn report(&self, regions: &[Region], table: &[Symbol]) -> String {
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
        let has = |name: &str| regions.iter().any(|r| r.name == name);
        let mut out = String::new();
        let _ = writeln!(out, "{:>9} {:>9} {:>9} {:>9} {:>9}", "text", "data", "bss", "ccm", "sdram");
        let _ = writeln!(
            out,
            "{:>9} {:>9} {:>9} {:>9} {:>9}",
            self.text, self.data, self.bss, self.ccm, self.sdram
        );
        let _ = writeln!(out, "flash (text+data):  {}", of("FLASH", self.flash()));
        let _ = writeln!(out, "RAM   (data+bss):   {} + stack", of("RAM", self.ram()));
        if self.ccm > 0 || has(CCM_REGION) {
            let _ = writeln!(out, "CCM RAM:            {}", of(CCM_REGION, self.ccm));
        }
        if self.sdram > 0 || has(SDRAM_REGION) {
            let _ = writeln!(out, "SDRAM:              {}", of(SDRAM_REGION, self.sdram));
        }
        let _ = writeln!(out, "{}", table_placement(table, regions));
        out
    }
}

/// `weight table: 65536 B in CCMRAM at 0x10000000 + 34304 B in RAM at … =
/// 99840 B`, or a note that the ELF names no table.
pub fn table_placement(table: &[Symbol], regions: &[Region]) -> String {
    if table.is_empty() {
        return "weight table: no PADA_TABLE_* symbol in the ELF (stripped?)".into();
    }
    let pieces: Vec<String> = table
        .iter()
        .map(|s| {
            let region = regions
                .iter()
                .find(|r| r.contains(s.addr))
                .map_or("no region", |r| r.name.as_str());
            format!("{} B in {region} at {:#010x} ({})", s.size, s.addr, s.name)
        })
        .collect();
    let total: u64 = table.iter().map(|s| s.size as u64).sum();
    format!("weight table: {} = {total} B", pieces.join(" + "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One section of a test ELF: name, type, flags, address, size, link,
    /// and its bytes in the file (for a symbol or string table).
    struct Spec<'a> {
        name: &'a str,
        ty: u32,
        flags: u32,
        addr: u32,
        size: u32,
        link: u32,
        bytes: Vec<u8>,
    }

    fn alloc(name: &str, ty: u32, flags: u32, addr: u32, size: u32) -> Spec<'_> {
        Spec { name, ty, flags, addr, size, link: 0, bytes: Vec::new() }
    }

    /// A minimal ELF32 LE with `sections` after the null section, and
    /// .shstrtab last. A section with bytes has them in the file and its
    /// size is their length.
    fn tiny_elf(sections: &[Spec]) -> Vec<u8> {
        let mut shstrtab = vec![0u8];
        let mut names = Vec::new();
        for name in sections.iter().map(|s| s.name).chain([".shstrtab"]) {
            names.push(shstrtab.len() as u32);
            shstrtab.extend_from_slice(name.as_bytes());
            shstrtab.push(0);
        }
        let mut elf = vec![0u8; 52];
        elf[..6].copy_from_slice(b"\x7fELF\x01\x01");
        let mut offsets = Vec::new();
        for s in sections {
            offsets.push(elf.len() as u32);
            elf.extend_from_slice(&s.bytes);
        }
        let shstrtab_off = elf.len() as u32;
        elf.extend_from_slice(&shstrtab);
        let shoff = elf.len() as u32;
        let shnum = sections.len() as u16 + 2;
        elf[0x20..0x24].copy_from_slice(&shoff.to_le_bytes());
        elf[0x2e..0x30].copy_from_slice(&40u16.to_le_bytes());
        elf[0x30..0x32].copy_from_slice(&shnum.to_le_bytes());
        elf[0x32..0x34].copy_from_slice(&(shnum - 1).to_le_bytes());
        elf.extend_from_slice(&[0u8; 40]);
        for (i, s) in sections.iter().enumerate() {
            let size = if s.bytes.is_empty() { s.size } else { s.bytes.len() as u32 };
            for field in [names[i], s.ty, s.flags, s.addr, offsets[i], size, s.link, 0, 4, 0] {
                elf.extend_from_slice(&field.to_le_bytes());
            }
        }
        let n = names[sections.len()];
        for field in [n, 3, 0, 0, shstrtab_off, shstrtab.len() as u32, 0, 0, 1, 0] {
            elf.extend_from_slice(&field.to_le_bytes());
        }
        elf
    }

    const PROGBITS: u32 = 1;
    const STRTAB: u32 = 3;
    const AX: u32 = SHF_ALLOC | 0x4;
    const WA: u32 = SHF_ALLOC | SHF_WRITE;

    fn f429_regions() -> Vec<Region> {
        parse_memory_x(include_str!("../../firmware/memory-f429.x"))
    }

    #[test]
    fn counts_like_berkeley_size_with_ccm_apart() {
        let elf = tiny_elf(&[
            alloc(".vector_table", PROGBITS, SHF_ALLOC, 0x0800_0000, 1024),
            alloc(".text", PROGBITS, AX, 0x0800_0400, 3000),
            alloc(".data", PROGBITS, WA, 0x2000_0000, 16),
            alloc(".bss", SHT_NOBITS, WA, 0x2000_0010, 400),
            alloc(".ccmram", SHT_NOBITS, WA, 0x1000_0000, 8192),
            alloc(".debug_info", PROGBITS, 0, 0, 99999),
        ]);
        let sections = section_sizes(&elf).unwrap();
        assert_eq!(sections.len(), 5, "{sections:?}");
        assert_eq!(sections[1].name, ".text");
        let regions = parse_memory_x(include_str!("../../memory.x"));
        let usage = Usage::classify(&sections, &regions);
        assert_eq!(usage, Usage { text: 4024, data: 16, bss: 400, ccm: 8192, sdram: 0 });
        assert_eq!((usage.flash(), usage.ram()), (4040, 416));
        let report = usage.report(&regions, &[]);
        assert!(report.contains("8192 B of   65536 B"), "{report}");
        // The F405 has no SDRAM region: no SDRAM line.
        assert!(!report.contains("SDRAM:"), "{report}");
    }

    #[test]
    fn counts_the_sdram_apart_and_places_the_table_by_its_symbols() {
        // A symbol table with the F429 LEO image's table and one other
        // symbol; its string table.
        let strtab = b"\0PADA_TABLE_SDRAM\0main\0".to_vec();
        let mut symtab = vec![0u8; SYM_LEN];
        for (name, addr, size) in [(1u32, 0xD000_0000u32, 8 << 20), (18, 0x0800_0400, 12)] {
            for field in [name, addr, size] {
                symtab.extend_from_slice(&field.to_le_bytes());
            }
            symtab.extend_from_slice(&[0, 0, 1, 0]);
        }
        let mut symtab_spec = alloc(".symtab", SHT_SYMTAB, 0, 0, 0);
        symtab_spec.bytes = symtab;
        // Sections are numbered from 1 after the null section: .strtab is 4.
        symtab_spec.link = 4;
        let mut strtab_spec = alloc(".strtab", STRTAB, 0, 0, 0);
        strtab_spec.bytes = strtab;
        let elf = tiny_elf(&[
            alloc(".text", PROGBITS, AX, 0x0800_0400, 3000),
            alloc(".sdram", SHT_NOBITS, WA, 0xD000_0000, 8 << 20),
            symtab_spec,
            strtab_spec,
        ]);
        let regions = f429_regions();
        let usage = Usage::classify(&section_sizes(&elf).unwrap(), &regions);
        assert_eq!(usage, Usage { text: 3000, sdram: 8 << 20, ..Usage::default() });
        let table = symbols(&elf, "PADA_TABLE_").unwrap();
        assert_eq!(table, vec![Symbol { name: "PADA_TABLE_SDRAM".into(), addr: 0xD000_0000, size: 8 << 20 }]);
        let report = usage.report(&regions, &table);
        assert!(report.contains("SDRAM:              8388608 B of 8388608 B (100.0%)"), "{report}");
        assert!(report.contains("CCM RAM:                  0 B of   65536 B"), "{report}");
        assert!(
            report.contains("weight table: 8388608 B in SDRAM at 0xd0000000 (PADA_TABLE_SDRAM) = 8388608 B"),
            "{report}"
        );
        // Without a symbol table the report says so instead of guessing.
        assert!(table_placement(&[], &regions).contains("no PADA_TABLE_"));
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
    fn reads_the_f429s_regions_two_128k_sectors_at_the_end_of_bank_2() {
        let regions = f429_regions();
        let find = |n: &str| regions.iter().find(|r| r.name == n).cloned().unwrap();
        // The program in bank 1 (sectors 0–11), all of it.
        assert_eq!((find("FLASH").origin, find("FLASH").length), (0x0800_0000, 1024 * 1024));
        // Sectors 22 and 23: 2 × 128 KB ending at the end of the 2 MB.
        let cp = find("CHECKPOINT");
        assert_eq!((cp.origin, cp.length), (0x081C_0000, 256 * 1024));
        assert_eq!(cp.origin + cp.length, 0x0800_0000 + 2 * 1024 * 1024);
        // SRAM1 + SRAM2 + SRAM3, CCM, and the DISC1's SDRAM on bank 2.
        assert_eq!(find("RAM").length, 192 * 1024);
        assert_eq!((find("CCMRAM").origin, find("CCMRAM").length), (0x1000_0000, 65536));
        assert_eq!((find("SDRAM").origin, find("SDRAM").length), (0xD000_0000, 8 * 1024 * 1024));
    }

    #[test]
    fn rejects_what_is_not_an_elf32() {
        assert!(section_sizes(b"not an elf at all").is_err());
        assert!(section_sizes(&[0x7f, b'E', b'L', b'F', 2, 1, 0, 0]).is_err());
        assert!(symbols(b"not an elf at all", "PADA").is_err());
    }
}
