"""THE opcode table: one row per STROLIC function code (body Table 1, Annex 1 Table 1).

The decoder (which codes are valid), the encoder and assembler (mnemonic → code), the
disassembler (code → mnemonic) and the VM (code → handler) all read this table. A row without a
handler is a robot or system function (EE, ED areas): the VM hands it to ``Host.call``; binding
one later means giving its row a handler.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from .functions import arithmetic as ar, bits, concurrency as cc, control as ct, data as dt
from .functions import geometry as ge, strings as st, system as sy
from .codes import I1, I2, I4, R4, R8


@dataclass(frozen=True)
class Opcode:
    code: int
    mnemonic: str
    effect: str                      # stack effect, Forth style, top of stack on the right
    handler: Callable | None = None  # (vm, proc) -> None | WAIT
    aliases: tuple[str, ...] = ()


def op(code: int, mnemonic: str, effect: str, handler: Callable | None = None,
       aliases: tuple[str, ...] = ()) -> Opcode:
    return Opcode(code, mnemonic, effect, handler, aliases)


VM_FUNCTIONS = [
    op(0xEF00, "ADD", "a b -- c", ar.add),
    op(0xEF01, "SUB", "a b -- c", ar.sub),
    op(0xEF02, "MUL", "a b -- c", ar.mul),
    op(0xEF03, "DIV", "a b -- c:R8", ar.div),
    op(0xEF04, "PWR", "a b -- c", ar.pwr),
    op(0xEF05, "MOD", "a b -- c", ar.mod),
    op(0xEF06, "IDIV", "a b -- c", ar.idiv),
    op(0xEF07, "INC", "a -- b", ar.inc),
    op(0xEF08, "DEC", "a -- b", ar.dec),
    op(0xEF09, "EQU", "a b -- flag", ar.equ),
    op(0xEF0A, "NEQ", "a b -- flag", ar.neq),
    op(0xEF0B, "LEQ", "a b -- flag", ar.leq),
    op(0xEF0C, "GEQ", "a b -- flag", ar.geq),
    op(0xEF0D, "LT", "a b -- flag", ar.lt),
    op(0xEF0E, "GT", "a b -- flag", ar.gt),
    op(0xEF0F, "AEQ", "a b -- flag", ar.aeq),
    op(0xEF10, "CPL", "a -- b", bits.cpl),
    op(0xEF11, "AND", "a b -- c", bits.and_),
    op(0xEF12, "OR", "a b -- c", bits.or_),
    op(0xEF13, "XOR", "a b -- c", bits.xor),
    op(0xEF14, "BSET", "a bit -- c", bits.bset),
    op(0xEF15, "BCLR", "a bit -- c", bits.bclr),
    op(0xEF16, "BTST", "a bit -- flag", bits.btst),
    op(0xEF17, "LSH", "a n -- c", bits.lsh),
    op(0xEF18, "RSH", "a n -- c", bits.rsh),
    op(0xEF19, "LSHA", "a n -- c", bits.lsha),
    op(0xEF1A, "RSHA", "a n -- c", bits.rsha),
    op(0xEF1B, "NOT", "a -- flag", ar.not_),
    op(0xEF1C, "CONC", "s1 s2 -- s", st.conc),
    op(0xEF1D, "LNG", "s -- n", st.lng),
    op(0xEF1E, "MID", "s start count -- s", st.mid),
    op(0xEF1F, "SIN", "a -- b", ar.sin),
    op(0xEF20, "COS", "a -- b", ar.cos),
    op(0xEF21, "TAN", "a -- b", ar.tan),
    op(0xEF22, "ATAN", "a -- b", ar.atan),
    op(0xEF23, "ATAN2", "y x -- c", ar.atan2),
    op(0xEF24, "LN", "a -- b", ar.ln),
    op(0xEF25, "EXP", "a -- b", ar.exp),
    op(0xEF26, "SQRT", "a -- b", ar.sqrt),
    op(0xEF27, "NEG", "a -- b", ar.neg),
    op(0xEF28, "ABS", "a -- b", ar.abs_),
    op(0xEF29, "SGN", "a -- b:I2", ar.sgn),
    op(0xEF2A, "INT", "a -- b", ar.int_),
    op(0xEF2B, "INT1", "a -- b:I1", ar.int_of(I1)),
    op(0xEF2C, "INT2", "a -- b:I2", ar.int_of(I2)),
    op(0xEF2D, "INT4", "a -- b:I4", ar.int_of(I4)),
    op(0xEF2E, "REAL", "a -- b", ar.real),
    op(0xEF2F, "REAL4", "a -- b:R4", ar.real_of(R4)),
    op(0xEF30, "REAL8", "a -- b:R8", ar.real_of(R8)),
    op(0xEF31, "SEPS", "eps --", ar.seps),
    op(0xEF32, "EPS", "-- eps:R8", ar.eps),
    op(0xEF33, "PI", "-- pi:R8", ar.pi),
    op(0xEF34, "DEGRAD", "deg -- rad", ar.degrad),
    op(0xEF35, "RADDEG", "rad -- deg", ar.raddeg),
    op(0xEF36, "VLEN", "v -- len:R4", ge.vlen),
    op(0xEF37, "VADD", "v1 v2 -- v", ge.vadd),
    op(0xEF38, "VSUB", "v1 v2 -- v", ge.vsub),
    op(0xEF39, "VTIMES", "v s -- v", ge.vtimes),
    op(0xEF3A, "VPRODI", "v1 v2 -- dot:R4", ge.vprodi),
    op(0xEF3B, "VPRODO", "v1 v2 -- cross", ge.vprodo),
    op(0xEF3C, "TPROD", "A B -- AB", ge.tprod),
    op(0xEF3D, "TINV", "A -- A^-1", ge.tinv),
    op(0xEF3E, "TPRODV", "A v -- Av", ge.tprodv),
    op(0xEF3F, "TRN", "pose -- trn", ge.trn),
    op(0xEF40, "PNT", "trn -- pose", ge.pnt),
    op(0xEF41, "LOC", "pose -- v", ge.loc),
    op(0xEF42, "DEV", "pose v -- pose", ge.dev),
    op(0xEF43, "DEVH", "pose v -- pose", ge.devh),
    op(0xEF44, "PADD", "rel base -- pose", ge.padd),
    op(0xEF45, "PSUB", "pose base -- rel", ge.psub),
    op(0xEF46, "CONSP", "a1..an n -- pose", ge.consp),
    op(0xEF47, "DESTP", "pose -- a1..an n", ge.destp),
    op(0xEF48, "CONSV", "x y z -- v", ge.consv),
    op(0xEF49, "DESTV", "v -- x y z", ge.destv),
    op(0xEF4A, "CONSA", "a1..an n #t -- array", dt.consa),
    op(0xEF4B, "DESTA", "array -- a1..an n", dt.desta),
    op(0xEF4C, "CONSU", "n -- #u", dt.consu),
    op(0xEF4D, "DESTU", "#u -- n", dt.destu),
    op(0xEF4E, "DUP", "a -- a a", dt.dup),
    op(0xEF4F, "DROP", "a --", dt.drop),
    op(0xEF50, "EXCH", "a b -- b a", dt.exch),
    op(0xEF51, "PUSH", "#u -- value", dt.push),
    op(0xEF52, "POP", "value #u --", dt.pop),
    op(0xEF53, "STORE", "#u value --", dt.store),
    op(0xEF54, "EXTB", "#u offset #t -- value", dt.extb, ("EXT",)),
    op(0xEF55, "EMBB", "#u offset value --", dt.embb, ("EMB",)),
    op(0xEF56, "EXTE", "#u index -- element", dt.exte),
    op(0xEF57, "EMBE", "#u index element --", dt.embe),
    op(0xEF58, "BRA", "offset --", ct.bra),
    op(0xEF59, "BRF", "cond offset --", ct.brf),
    op(0xEF5A, "BRT", "cond offset --", ct.brt),
    op(0xEF5B, "RET", "--", ct.ret),
    op(0xEF5C, "END", "--", ct.end),
    op(0xEF5D, "NESTIN", "level --", ct.nestin),
    op(0xEF5E, "NESTOUT", "--", ct.nestout),
    op(0xEF5F, "NPUSH", "#u level -- value", ct.npush),
    op(0xEF60, "NPOP", "value #u level --", ct.npop),
    op(0xEF61, "DCL", "VAR #u1..#un --", ct.dcl),
    op(0xEF62, "FREE", "VAR #u1..#un --", ct.free),
    op(0xEF63, "VAR", "-- VAR", ct.var),
    op(0xEF64, "FDEF", "#u -- (reads the next function data)", ct.fdef),
    op(0xEF65, "BAL", "offset --", ct.bal),
    op(0xEF66, "GRET", "--", ct.gret),
    op(0xEF67, "ALLOC", "size #t #u -- n", dt.alloc),
    op(0xEF68, "ALLOCZ", "size #t #u -- n", dt.alloc),
    op(0xEF69, "ACLR", "#u --", dt.aclr),
    op(0xEF6A, "ARELS", "#u --", dt.arels),
    op(0xEF6B, "ASIZE", "#u -- n", dt.asize),
    op(0xEF6C, "VERID", "-- s", sy.verid),
    op(0xEF6D, "SYSID", "-- s", sy.sysid),
    op(0xEF6E, "INIT", "... --", sy.init),
    op(0xEF6F, "TRON", "--", sy.tron),
    op(0xEF70, "TROFF", "--", sy.troff),
    op(0xEF71, "TRACE", "a --", sy.trace),
    op(0xEF72, "SYNC", "--", sy.sync),
    op(0xEF73, "ACK", "--", sy.reply_code),
    op(0xEF74, "NAK", "--", sy.reply_code),
    op(0xEF75, "RESULT", "a --", sy.result),
    op(0xEF76, "FXQT", "#f process -- err", cc.fxqt),
    op(0xEF77, "TXQT", "task -- err", cc.txqt),
    op(0xEF78, "FPREDC", "process priority -- state", cc.fprecd, ("FPRECD",)),
    op(0xEF79, "TPRECD", "task priority -- state", cc.tprecd, ("TPREDC",)),
    op(0xEF7A, "FCYCLE", "process ms -- state", cc.fcycle),
    op(0xEF7B, "TCYCLE", "task ms -- state", cc.tcycle),
    op(0xEF7C, "FDONE", "process -- state", cc.fdone),
    op(0xEF7D, "TDONE", "task -- state", cc.tdone),
    op(0xEF7E, "FKILL", "process -- err", cc.fkill),
    op(0xEF7F, "TKILL", "task -- err", cc.tkill),
    op(0xEF80, "FSUSPEND", "process -- err", cc.fsuspend),
    op(0xEF81, "TSUSPEND", "task -- err", cc.tsuspend),
    op(0xEF82, "FRESUME", "process -- err", cc.fresume),
    op(0xEF83, "TRESUME", "task -- err", cc.tresume),
    op(0xEF84, "LOCK", "flag --", cc.lock),
    op(0xEF85, "UNLOCK", "flag -- err", cc.unlock),
    op(0xEF86, "EWAIT", "flag --", cc.ewait),
    op(0xEF87, "EWAITA", "f1..fn n --", cc.ewaita),
    op(0xEF88, "EWAITO", "f1..fn n --", cc.ewaito),
    op(0xEF89, "EPOP", "-- flag", cc.epop),
    op(0xEF8A, "ESIG", "flag --", cc.esig),
    op(0xEF8B, "ECLR", "f1..fn n --", cc.eclr),
    op(0xEF8C, "CHIN", "channel -- value", cc.chin),
    op(0xEF8D, "CHOUT", "channel value --", cc.chout),
    op(0xEF8E, "SHARE", "#u number --", cc.share),
]

# System (EE) and robot-control (ED) functions: named for the assembler and disassembler; their
# handlers come with the robot binding (through Host.call until then).
SYSTEM_AND_ROBOT_NAMES = {
    0xEE00: "TIME DATE CLOCK STIME SDATE CLRCLK PACKTM UNPKTM PACKDT UNPKDT CNFG DOUT DIN IOWAIT "
            "ACT ACTRS REACT ACTCODE ACTION TIMER RTIMER TACTION FSTAT OUTPUT INPUT LOUTPUT LINPUT "
            "FOPEN FCLOSE PUTC GETC DECODE1 ENCODE1 DECODE2 ENCODE2",
    0xED00: "JSPEED SPEED ACCEL1 ACCEL2 DECEL1 DECEL2 SCONF SCONF2 SCONF3 GCONF GCONF2 GCONF3 HERE "
            "JHERE CALIB PAUSE DELAY AJMOVE IJMOVE ALMOVE ILMOVE HMOVE CMOVE1 CMOVE3 ADRIVE IDRIVE "
            "SACC GACC $WAIT $DONE HANDOPEN HANDCLOSE GRASP HANDDEF HANDREF HANDCHG",
}
HOST_FUNCTIONS = [op(base + i, name, "see part 3 of the digest")
                  for base, names in SYSTEM_AND_ROBOT_NAMES.items()
                  for i, name in enumerate(names.split())]

TABLE = VM_FUNCTIONS + HOST_FUNCTIONS
BY_CODE = {row.code: row for row in TABLE}
BY_MNEMONIC = {name: row for row in TABLE for name in (row.mnemonic, *row.aliases)}
