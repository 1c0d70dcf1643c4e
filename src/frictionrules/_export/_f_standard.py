"""Abaqus/Standard user subroutines in fixed-form Fortran 77: FRIC (the tangential law at the
contact pressure Abaqus passes) and UINTER (the whole interface law with the normal penalty).

Both call the return mapping of ``_f_return.py`` (``@P@RM``) and substep where it fails,
halving as :class:`~frictionrules.ContactModel` does. ``@PARAMS@``, ``@P@``,
``@NPAR@`` and ``@Q0@`` (the virgin internal variables) are filled by ``_fortran.fill``.
"""

FRIC = """\
      SUBROUTINE FRIC(LM, TAU, DDTDDG, DDTDDP, DSLIP, SED, SFD,
     1 DDTDDT, PNEWDT, STATEV, DGAM, TAULM, PRESS, DPRESS, DDPDDH,
     2 SLIP, KSTEP, KINC, TIME, DTIME, NOEL, CINAME, SLNAME, MSNAME,
     3 NPT, NODE, NPATCH, COORDS, RCOORD, DROT, TEMP, PREDEF, NFDIR,
     4 MCRD, NPRED, NSTATV, CHRLNGTH, PROPS, NPROPS)
C
      INCLUDE 'ABA_PARAM.INC'
C
      CHARACTER*80 CINAME, SLNAME, MSNAME
      DIMENSION TAU(NFDIR), DDTDDG(NFDIR, NFDIR), DDTDDP(NFDIR),
     1 DSLIP(NFDIR), DDTDDT(NFDIR, 2), STATEV(*), DGAM(NFDIR),
     2 TAULM(NFDIR), SLIP(NFDIR), TIME(2), COORDS(MCRD),
     3 RCOORD(MCRD), DROT(2, 2), TEMP(2), PREDEF(2, *), PROPS(NPROPS)
C
@PARAMS@
      INTEGER NPAR
      PARAMETER (NPAR = @NPAR@)
      DOUBLE PRECISION Q0(NQS)
      DOUBLE PRECISION P(NPAR + 1), E(2), Q(NQS), EN(2), QN(NQS)
      DOUBLE PRECISION STR(3), SIG(3), DSIG(3, 3), DV(3), DG(2), ET(2)
      DOUBLE PRECISION AKT, PSTART, PK, FRAC, DLAM, DISS
      INTEGER KIND, IDEPTH, IPOS, IFULL, I, J, NQV, KAP
      DATA Q0 /@Q0@/
      NQV = NQ
      KAP = HASKAP
      IF (.FALSE.) WRITE (*, *) TAULM(1), SLIP(1), KSTEP, KINC, TIME,
     &     DTIME, NOEL, CINAME, SLNAME, MSNAME, NPT, NODE, NPATCH,
     &     COORDS(1), RCOORD(1), DROT(1, 1), TEMP(1), PREDEF(1, 1),
     &     NPRED, CHRLNGTH, DDPDDH
C     Open at the previous increment: nothing to do.
      IF (LM .EQ. 2) RETURN
      LM = 0
      IF (NPROPS .LT. NPAR + 1 .OR. NSTATV .LT. NQ + 2) THEN
         WRITE (*, *) 'FRIC (frictionrules): needs PROPERTIES = ',
     &        NPAR + 1, ' and DEPVAR = ', NQ + 2
         CALL XIT
      END IF
      DO 10 I = 1, NPAR + 1
         P(I) = PROPS(I)
   10 CONTINUE
      AKT = PROPS(NPAR + 1)
      DO 20 J = 1, NQV
         Q(J) = STATEV(J) + Q0(J)
   20 CONTINUE
      E(1) = STATEV(NQ + 1)
      E(2) = STATEV(NQ + 2)
C     2-D (NFDIR = 1): no relative motion out of the plane; the
C     out-of-plane elastic slip E(2) is state, its force a reaction.
      DG(1) = DGAM(1)
      DG(2) = 0.0D0
      IF (NFDIR .EQ. 2) DG(2) = DGAM(2)
      DV(1) = AKT
      DV(2) = AKT
      DV(3) = 0.0D0
      DO 30 I = 1, NFDIR
         TAU(I) = 0.0D0
         DDTDDP(I) = 0.0D0
         DSLIP(I) = 0.0D0
         DDTDDT(I, 1) = 0.0D0
         DDTDDT(I, 2) = 0.0D0
         DO 25 J = 1, NFDIR
            DDTDDG(I, J) = 0.0D0
   25    CONTINUE
   30 CONTINUE
      SED = 0.0D0
      SFD = 0.0D0
C     Substeps where Newton fails (halving), the pressure
C     linear over the increment from PRESS - DPRESS to PRESS.
      PSTART = PRESS - DPRESS
      IFULL = 2**MAXDEP
      IPOS = 0
      IDEPTH = 0
      KIND = KOPEN
   40 IF (IPOS .GE. IFULL) GO TO 90
      FRAC = 1.0D0/2**IDEPTH
      PK = PSTART + DPRESS*DBLE(IPOS + IFULL/2**IDEPTH)/DBLE(IFULL)
      ET(1) = E(1) + FRAC*DG(1)
      ET(2) = E(2) + FRAC*DG(2)
      DO 50 J = 1, NQV
         QN(J) = Q(J)
   50 CONTINUE
      DISS = 0.0D0
      IF (PK .LE. 0.0D0) THEN
         KIND = KOPEN
         EN(1) = 0.0D0
         EN(2) = 0.0D0
         SIG(1) = 0.0D0
         SIG(2) = 0.0D0
      ELSE
         STR(1) = AKT*ET(1)
         STR(2) = AKT*ET(2)
         STR(3) = PK
         CALL @P@RM(STR, Q, P, DV, SIG, QN, DLAM, DSIG, .TRUE., KIND)
         IF (KIND .EQ. KFAIL) THEN
            IF (IDEPTH .GE. MAXDEP) THEN
               PNEWDT = 0.25D0
               RETURN
            END IF
            IDEPTH = IDEPTH + 1
            GO TO 40
         END IF
         IF (KIND .EQ. KELAS) THEN
            EN(1) = ET(1)
            EN(2) = ET(2)
         ELSE IF (KIND .EQ. KPLAS) THEN
            EN(1) = SIG(1)/AKT
            EN(2) = SIG(2)/AKT
            DISS = SIG(1)*(ET(1) - EN(1)) + SIG(2)*(ET(2) - EN(2))
         ELSE
            EN(1) = 0.0D0
            EN(2) = 0.0D0
            SIG(1) = 0.0D0
            SIG(2) = 0.0D0
            IF (KAP .EQ. 1) QN(KAPPA + 1) = Q(KAPPA + 1)
     &           + SQRT(ET(1)**2 + ET(2)**2)
         END IF
      END IF
      DO 60 I = 1, NFDIR
         DSLIP(I) = DSLIP(I) + ET(I) - EN(I)
   60 CONTINUE
      SFD = SFD + DISS
      E(1) = EN(1)
      E(2) = EN(2)
      DO 70 J = 1, NQV
         Q(J) = QN(J)
   70 CONTINUE
      IPOS = IPOS + IFULL/2**IDEPTH
   80 IF (IDEPTH .GT. 0) THEN
         IF (MOD(IPOS, IFULL/2**(IDEPTH - 1)) .EQ. 0) THEN
            IDEPTH = IDEPTH - 1
            GO TO 80
         END IF
      END IF
      GO TO 40
C     The end of the increment: forces, tangent of the last substep.
   90 DO 110 I = 1, NFDIR
         TAU(I) = SIG(I)
         IF (KIND .EQ. KELAS) THEN
            DDTDDG(I, I) = AKT
         ELSE IF (KIND .EQ. KPLAS) THEN
            DDTDDP(I) = DSIG(I, 3)
            DO 100 J = 1, NFDIR
               DDTDDG(I, J) = DSIG(I, J)*AKT
  100       CONTINUE
         END IF
  110 CONTINUE
      SED = 0.5D0*AKT*(E(1)**2 + E(2)**2)
      DO 120 J = 1, NQV
         STATEV(J) = Q(J) - Q0(J)
  120 CONTINUE
      STATEV(NQ + 1) = E(1)
      STATEV(NQ + 2) = E(2)
      RETURN
      END
"""

UINTER = """\
      SUBROUTINE UINTER(STRESS, DDSDDR, AMKI, AMSKI, FLUX, DDFDDT,
     1 DDSDDT, DDFDDR, STATEV, SED, SFD, SPD, SVD, SCD, PNEWDT, RDISP,
     2 DRDISP, TEMP, DTEMP, PREDEF, DPRED, TIME, DTIME, FREQR, CINAME,
     3 SLNAME, MSNAME, PROPS, COORDS, ALOCALDIR, DROT, AREA, CHRLNGTH,
     4 NODE, NDIR, NSTATV, NPRED, NPROPS, MCRD, KSTEP, KINC, KIT,
     5 LINPER, LOPENCLOSE, LSTATE, LSDI, LPRINT)
C
      INCLUDE 'ABA_PARAM.INC'
C
      CHARACTER*80 CINAME, SLNAME, MSNAME
      DIMENSION STRESS(NDIR), DDSDDR(NDIR, NDIR), FLUX(2),
     1 DDFDDT(2, 2), DDSDDT(NDIR, 2), DDFDDR(2, NDIR), STATEV(NSTATV),
     2 RDISP(NDIR), DRDISP(NDIR), TEMP(2), DTEMP(2), PREDEF(2, NPRED),
     3 DPRED(2, NPRED), TIME(2), PROPS(NPROPS), COORDS(MCRD),
     4 ALOCALDIR(MCRD, MCRD), DROT(2, 2), AMKI(NDIR, NDIR),
     5 AMSKI(NDIR, NDIR)
C
@PARAMS@
      INTEGER NPAR
      PARAMETER (NPAR = @NPAR@)
      DOUBLE PRECISION Q0(NQS)
      DOUBLE PRECISION P(NPAR + 2), E(3), PL(3), Q(NQS), QN(NQS)
      DOUBLE PRECISION DU(3), ET(3), EN(3), STR(3), SIG(3), DSIG(3, 3)
      DOUBLE PRECISION DV(3), C(3, 3), EK(3), AKT, AKN, FRAC, DLAM
      DOUBLE PRECISION DISST, DISSN
      INTEGER KIND, IDEPTH, IPOS, IFULL, I, J, NQV, KAP, IS(3), IR(3)
      DATA IS /3, 1, 2/, IR /3, 1, 2/
      DATA Q0 /@Q0@/
      NQV = NQ
      KAP = HASKAP
      IF (.FALSE.) WRITE (*, *) TEMP(1), DTEMP(1), PREDEF(1, 1),
     &     DPRED(1, 1), TIME(1), DTIME, FREQR, CINAME, SLNAME, MSNAME,
     &     COORDS(1), ALOCALDIR(1, 1), DROT(1, 1), AREA, CHRLNGTH,
     &     NODE, KSTEP, KINC, KIT, LINPER, LPRINT, RDISP(1)
      IF (NPROPS .LT. NPAR + 2 .OR. NSTATV .LT. NQ + 6) THEN
         WRITE (*, *) 'UINTER (frictionrules): needs PROPERTIES = ',
     &        NPAR + 2, ' and DEPVAR = ', NQ + 6
         CALL XIT
      END IF
      DO 10 I = 1, NPAR + 2
         P(I) = PROPS(I)
   10 CONTINUE
      AKN = PROPS(NPAR + 1)
      AKT = PROPS(NPAR + 2)
      DO 20 I = 1, 3
         E(I) = STATEV(NQ + I)
         PL(I) = STATEV(NQ + 3 + I)
   20 CONTINUE
      DO 30 J = 1, NQV
         Q(J) = STATEV(J) + Q0(J)
   30 CONTINUE
C     (dt1, dt2, dn) with dn positive on opening; RDISP(1) is the
C     overclosure; 2-D (NDIR = 2): no relative motion out of the plane.
      DU(1) = DRDISP(2)
      DU(2) = 0.0D0
      IF (NDIR .EQ. 3) DU(2) = DRDISP(3)
      DU(3) = -DRDISP(1)
      DV(1) = AKT
      DV(2) = AKT
      DV(3) = AKN
      EK(1) = AKT
      EK(2) = AKT
      EK(3) = -AKN
      SFD = 0.0D0
      SPD = 0.0D0
      SVD = 0.0D0
      SCD = 0.0D0
C     Substeps where Newton fails (halving).
      IFULL = 2**MAXDEP
      IPOS = 0
      IDEPTH = 0
      KIND = KOPEN
   40 IF (IPOS .GE. IFULL) GO TO 90
      FRAC = 1.0D0/2**IDEPTH
      DO 45 I = 1, 3
         ET(I) = E(I) + FRAC*DU(I)
   45 CONTINUE
      DO 50 J = 1, NQV
         QN(J) = Q(J)
   50 CONTINUE
      DISST = 0.0D0
      DISSN = 0.0D0
      STR(1) = AKT*ET(1)
      STR(2) = AKT*ET(2)
      STR(3) = -AKN*ET(3)
      KIND = KOPEN
      IF (STR(3) .GT. 0.0D0) THEN
         CALL @P@RM(STR, Q, P, DV, SIG, QN, DLAM, DSIG, .TRUE., KIND)
         IF (KIND .EQ. KFAIL) THEN
            IF (IDEPTH .GE. MAXDEP) THEN
               PNEWDT = 0.25D0
               RETURN
            END IF
            IDEPTH = IDEPTH + 1
            GO TO 40
         END IF
      END IF
      IF (KIND .EQ. KELAS) THEN
         DO 55 I = 1, 3
            EN(I) = ET(I)
   55    CONTINUE
      ELSE IF (KIND .EQ. KPLAS) THEN
         EN(1) = SIG(1)/AKT
         EN(2) = SIG(2)/AKT
         EN(3) = -SIG(3)/AKN
         DISST = SIG(1)*(ET(1) - EN(1)) + SIG(2)*(ET(2) - EN(2))
         DISSN = -SIG(3)*(ET(3) - EN(3))
      ELSE
C        Open, or a return that ends at the apex of a cone.
         DO 60 I = 1, 3
            SIG(I) = 0.0D0
   60    CONTINUE
         EN(1) = 0.0D0
         EN(2) = 0.0D0
         EN(3) = MAX(ET(3), 0.0D0)
         DO 62 J = 1, NQV
            QN(J) = Q(J)
   62    CONTINUE
         IF (KIND .EQ. KAPEX .AND. KAP .EQ. 1) QN(KAPPA + 1) =
     &        Q(KAPPA + 1) + SQRT(ET(1)**2 + ET(2)**2)
         IF (KIND .EQ. KAPEX) KIND = KOPEN
      END IF
      DO 65 I = 1, 3
         PL(I) = PL(I) + ET(I) - EN(I)
         E(I) = EN(I)
   65 CONTINUE
      DO 70 J = 1, NQV
         Q(J) = QN(J)
   70 CONTINUE
      SFD = SFD + DISST
      SPD = SPD + DISSN
      IPOS = IPOS + IFULL/2**IDEPTH
   80 IF (IDEPTH .GT. 0) THEN
         IF (MOD(IPOS, IFULL/2**(IDEPTH - 1)) .EQ. 0) THEN
            IDEPTH = IDEPTH - 1
            GO TO 80
         END IF
      END IF
      GO TO 40
C     The end of the increment: stress (pressure, shear 1, shear 2) and
C     d(stress)/d(overclosure, slip 1, slip 2) of the last substep.
   90 DO 110 I = 1, 3
         DO 100 J = 1, 3
            C(I, J) = 0.0D0
            IF (KIND .EQ. KPLAS) C(I, J) = DSIG(I, J)*EK(J)
  100    CONTINUE
         IF (KIND .EQ. KELAS) C(I, I) = EK(I)
  110 CONTINUE
      DO 130 I = 1, NDIR
         STRESS(I) = SIG(IS(I))
         IF (KIND .EQ. KOPEN) STRESS(I) = 0.0D0
         DO 120 J = 1, NDIR
            DDSDDR(I, J) = C(IS(I), IR(J))
            IF (J .EQ. 1) DDSDDR(I, J) = -DDSDDR(I, J)
  120    CONTINUE
         DO 125 J = 1, NDIR
            AMKI(I, J) = 0.0D0
            AMSKI(I, J) = 0.0D0
  125    CONTINUE
         DDSDDT(I, 1) = 0.0D0
         DDSDDT(I, 2) = 0.0D0
         DDFDDR(1, I) = 0.0D0
         DDFDDR(2, I) = 0.0D0
  130 CONTINUE
      FLUX(1) = 0.0D0
      FLUX(2) = 0.0D0
      DDFDDT(1, 1) = 0.0D0
      DDFDDT(1, 2) = 0.0D0
      DDFDDT(2, 1) = 0.0D0
      DDFDDT(2, 2) = 0.0D0
      SED = 0.5D0*(AKT*(E(1)**2 + E(2)**2) + AKN*E(3)**2)
      IF (KIND .EQ. KOPEN) SED = 0.0D0
      LSTATE = 1
      IF (KIND .EQ. KOPEN) LSTATE = 0
      LSDI = 0
      IF (LOPENCLOSE .NE. -1 .AND. LOPENCLOSE .NE. LSTATE) LSDI = 1
      DO 140 J = 1, NQV
         STATEV(J) = Q(J) - Q0(J)
  140 CONTINUE
      DO 150 I = 1, 3
         STATEV(NQ + I) = E(I)
         STATEV(NQ + 3 + I) = PL(I)
  150 CONTINUE
      RETURN
      END
"""
